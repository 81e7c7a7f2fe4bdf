#pragma once
// A four-legged subject (dog-like: body, neck, head with snout, four two-segment legs in a
// trotting gait, wagging tail) walking a wandering path: a second, non-human silhouette
// kind for the calibration tests.

#include <memory>

#include "sim/scene/subject.h"
#include "sim/scene/walk_path.h"

namespace silnet::sim {

// Parameters of one quadruped.
struct QuadrupedOptions {
  double size = 1.3;  // scale; 1.0 is a medium dog (shoulder height about 0.55 m)
  WalkPathOptions path;
  uint64_t seed = 1;
};

// A trotting quadruped.
class QuadrupedSubject : public Subject {
 public:
  QuadrupedSubject(const QuadrupedOptions& options, std::vector<Material>* materials);

  void AppendPrimitives(double time, std::vector<Primitive>* out) const override;
  const std::vector<std::string>& PartNames() const override;
  std::string Kind() const override { return "quadruped"; }

 private:
  QuadrupedOptions options_;
  WalkPath path_;
  int fur_ = 0, dark_ = 0;
};

}  // namespace silnet::sim
