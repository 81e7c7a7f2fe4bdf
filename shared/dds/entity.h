#pragma once
// Move-only ownership of one DDS entity handle; the destructor deletes the entity (and,
// as Cyclone does, all its children). Destructors never throw.

#include <dds/dds.h>

#include <utility>

namespace silnet::dds {

// Owns a dds_entity_t.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      Reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  ~Entity() { Reset(); }

  dds_entity_t handle() const { return handle_; }
  explicit operator bool() const { return handle_ > 0; }
  // Deletes the entity now; the object becomes empty.
  void Reset() {
    if (handle_ > 0) dds_delete(handle_);
    handle_ = 0;
  }

 private:
  dds_entity_t handle_ = 0;
};

}  // namespace silnet::dds
