#pragma once
// A DDS domain participant joined with a DomainConfig.

#include <memory>

#include "shared/dds/domain_config.h"
#include "shared/dds/entity.h"

namespace silnet::dds {

class DomainHandle;

// Joins a domain for the lifetime of the object. Several participants of one process may
// share a domain id only if they use the same DomainConfig (Cyclone configures a domain
// once per process); a conflicting config throws DdsError.
class Participant {
 public:
  explicit Participant(const DomainConfig& config = DomainConfig::FromEnvironment());
  Participant(Participant&&) noexcept = default;
  Participant& operator=(Participant&&) noexcept = default;
  ~Participant();

  dds_entity_t handle() const { return entity_.handle(); }
  const DomainConfig& config() const { return config_; }

 private:
  DomainConfig config_;
  std::shared_ptr<DomainHandle> domain_;  // must outlive entity_
  Entity entity_;
};

}  // namespace silnet::dds
