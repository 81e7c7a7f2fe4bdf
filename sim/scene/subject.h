#pragma once
// A simulated subject: something whose shape at any time is a set of convex primitives.

#include <string>
#include <vector>

#include "sim/scene/primitive.h"
#include "sim/scene/solid_texture.h"

namespace silnet::sim {

// A moving (or static) solid made of primitives.
class Subject {
 public:
  virtual ~Subject() = default;
  // Appends the subject's primitives (world frame) at reference time `time` (seconds).
  virtual void AppendPrimitives(double time, std::vector<Primitive>* out) const = 0;
  // Names of the subject's parts, indexed by Primitive::part.
  virtual const std::vector<std::string>& PartNames() const = 0;
  // A short name of the kind of subject ("human", "quadruped", "statue").
  virtual std::string Kind() const = 0;
};

// Adds `material` to `materials` and returns its index.
inline int AddMaterial(std::vector<Material>* materials, const Material& material) {
  materials->push_back(material);
  return static_cast<int>(materials->size()) - 1;
}

}  // namespace silnet::sim
