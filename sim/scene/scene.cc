#include "sim/scene/scene.h"

#include <cmath>
#include <numbers>

#include "shared/util/check.h"
#include "sim/scene/human_subject.h"
#include "sim/scene/quadruped_subject.h"
#include "sim/scene/stills_statue.h"

namespace silnet::sim {

SubjectKind ParseSubjectKind(const std::string& name) {
  if (name == "human") return SubjectKind::kHuman;
  if (name == "quadruped") return SubjectKind::kQuadruped;
  if (name == "statue") return SubjectKind::kStatue;
  if (name == "stills-statue") return SubjectKind::kStillsStatue;
  throw InputError("unknown subject '" + name +
                   "' (use human, quadruped, statue or stills-statue)");
}

std::string ToString(SubjectKind kind) {
  switch (kind) {
    case SubjectKind::kHuman:
      return "human";
    case SubjectKind::kQuadruped:
      return "quadruped";
    case SubjectKind::kStatue:
      return "statue";
    case SubjectKind::kStillsStatue:
      return "stills-statue";
  }
  return "unknown";
}

Scene::Scene(const SceneOptions& options)
    : options_(options),
      environment_(EnvironmentOptions{.half_size = 8.0,
                                      .height = 6.0,
                                      .lighting_changes = options.lighting_changes,
                                      .seed = options.seed * 7919u + 17u}) {
  SILNET_CHECK(options.count >= 1);
  SILNET_CHECK(options.time_end > options.time_begin);
  const bool single =
      options.subject == SubjectKind::kStatue || options.subject == SubjectKind::kStillsStatue;
  const int count = single ? 1 : options.count;
  for (int i = 0; i < count; ++i) {
    WalkPathOptions path;
    path.radius = options.walk_radius;
    path.mean_speed = options.mean_speed;
    path.time_begin = options.time_begin;
    path.time_end = options.time_end;
    path.seed = options.seed * 1000003u + static_cast<uint64_t>(i);
    if (count > 1) {
      // Several subjects wander around centres spread on a circle, in smaller discs.
      const double angle = 2.0 * std::numbers::pi * i / count;
      path.center = 0.45 * options.walk_radius * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      path.radius = 0.55 * options.walk_radius;
    }
    const uint64_t seed = options.seed * 31u + static_cast<uint64_t>(i) * 7u + 3u;
    switch (options.subject) {
      case SubjectKind::kHuman: {
        HumanOptions human;
        human.height = 1.6 + 0.05 * static_cast<double>(seed % 7);
        human.path = path;
        human.seed = seed;
        subjects_.push_back(std::make_unique<HumanSubject>(human, &materials_));
        break;
      }
      case SubjectKind::kQuadruped:
        subjects_.push_back(std::make_unique<QuadrupedSubject>(
            QuadrupedOptions{.size = 1.3, .path = path, .seed = seed}, &materials_));
        break;
      case SubjectKind::kStatue: {
        HumanOptions statue;
        statue.path = path;
        statue.seed = seed;
        statue.frozen = true;
        statue.frozen_pose.heading = 0.4;
        statue.frozen_pose.gait_phase = 0.9;
        statue.frozen_pose.gait_amount = 0.9;
        statue.frozen_pose.raise_left = 1.0;
        statue.frozen_pose.raise_right = 0.3;
        statue.frozen_pose.head_yaw = 0.3;
        statue.stone = true;
        subjects_.push_back(std::make_unique<HumanSubject>(statue, &materials_));
        break;
      }
      case SubjectKind::kStillsStatue:
        subjects_.push_back(
            std::make_unique<StillsStatue>(StillsStatueOptions{.seed = seed}, &materials_));
        break;
    }
  }
}

Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;

std::vector<Primitive> Scene::PrimitivesAt(double time) const {
  std::vector<Primitive> primitives;
  for (size_t i = 0; i < subjects_.size(); ++i) {
    const size_t first = primitives.size();
    subjects_[i]->AppendPrimitives(time, &primitives);
    for (size_t p = first; p < primitives.size(); ++p)
      primitives[p].subject = static_cast<int>(i);
  }
  return primitives;
}

}  // namespace silnet::sim
