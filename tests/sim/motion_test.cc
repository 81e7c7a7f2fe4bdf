// The simulated subjects really move: they walk, turn, swing their limbs and raise their
// arms, smoothly enough that sub-frame times are meaningful.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "shared/util/check.h"
#include "sim/scene/human_subject.h"
#include "sim/scene/scene.h"

namespace silnet::sim {
namespace {

SceneOptions Options(SubjectKind kind, int count = 1, uint64_t seed = 5) {
  SceneOptions o;
  o.subject = kind;
  o.count = count;
  o.time_begin = -1.0;
  o.time_end = 41.0;
  o.seed = seed;
  return o;
}

const Primitive& Part(const std::vector<Primitive>& primitives, int subject,
                      const std::string& name, const Scene& scene) {
  const auto& names = scene.subject(subject).PartNames();
  const int part = static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
  for (const Primitive& p : primitives) {
    if (p.subject == subject && p.part == part) return p;
  }
  throw std::runtime_error("no part " + name);
}

TEST(SubjectMotion, TheHumanWalksTurnsSwingsAndRaisesItsArms) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    const Scene scene(Options(SubjectKind::kHuman, 1, seed));
    double path_length = 0.0, heading_change = 0.0, max_radius = 0.0;
    double min_thigh = 1e9, max_thigh = -1e9;
    bool arm_raised = false;
    Eigen::Vector3d previous_pelvis = Part(scene.PrimitivesAt(0.0), 0, "pelvis", scene).center;
    double previous_heading = 0.0;
    for (double t = 0.0; t <= 40.0; t += 1.0 / 30.0) {
      const auto primitives = scene.PrimitivesAt(t);
      const Primitive& pelvis = Part(primitives, 0, "pelvis", scene);
      const Primitive& thigh = Part(primitives, 0, "left_thigh", scene);
      const Primitive& head = Part(primitives, 0, "head", scene);
      const Primitive& hand = Part(primitives, 0, "left_hand", scene);
      path_length += (pelvis.center - previous_pelvis).head<2>().norm();
      previous_pelvis = pelvis.center;
      max_radius = std::max(max_radius, pelvis.center.head<2>().norm());
      const double heading = std::atan2(pelvis.axes(1, 0), pelvis.axes(0, 0));
      if (t > 0)
        heading_change +=
            std::abs(std::remainder(heading - previous_heading, 2 * std::numbers::pi));
      previous_heading = heading;
      const Eigen::Vector3d thigh_dir = (thigh.b - thigh.a).normalized();
      const double swing = std::atan2(thigh_dir.dot(pelvis.axes.col(0)), -thigh_dir.z());
      min_thigh = std::min(min_thigh, swing);
      max_thigh = std::max(max_thigh, swing);
      if (hand.center.z() > head.center.z()) arm_raised = true;
    }
    EXPECT_GT(path_length, 15.0) << "seed " << seed;  // walks ~0.9 m/s for 40 s
    EXPECT_LT(max_radius, scene.options().walk_radius + 0.2) << "seed " << seed;  // in its disc
    EXPECT_GT(heading_change, 2.0 * std::numbers::pi) << "seed " << seed;         // turns around
    EXPECT_GT(max_thigh - min_thigh, 0.4) << "seed " << seed;                     // legs swing
    EXPECT_TRUE(arm_raised) << "seed " << seed;
  }
}

TEST(SubjectMotion, MotionIsContinuousInTime) {
  const Scene scene(Options(SubjectKind::kHuman));
  for (double t = 0.0; t < 20.0; t += 0.37) {
    const auto a = scene.PrimitivesAt(t), b = scene.PrimitivesAt(t + 0.001);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_LT((a[i].center - b[i].center).norm(), 0.01) << "t=" << t << " part " << a[i].part;
      EXPECT_LT((a[i].a - b[i].a).norm(), 0.01);
    }
  }
}

TEST(SubjectMotion, TheQuadrupedWalksAndTheStatueStandsStill) {
  const Scene dog(Options(SubjectKind::kQuadruped));
  EXPECT_EQ(dog.PrimitivesAt(0.0).size(), 13u);
  double farthest = 0.0;
  for (double t = 0.0; t < 10.0; t += 0.5) {
    farthest = std::max(farthest,
                        (dog.PrimitivesAt(0.0)[0].center - dog.PrimitivesAt(t)[0].center).norm());
  }
  EXPECT_GT(farthest, 1.0);
  EXPECT_EQ(dog.subject(0).Kind(), "quadruped");
  const Scene statue(Options(SubjectKind::kStatue, 3));
  EXPECT_EQ(statue.subject_count(), 1);
  EXPECT_TRUE(statue.is_static());
  const auto a = statue.PrimitivesAt(0.0), b = statue.PrimitivesAt(7.0);
  for (size_t i = 0; i < a.size(); ++i)
    EXPECT_EQ((a[i].center - b[i].center).norm(), 0.0);
}

TEST(SubjectMotion, SeveralPeopleAreDistinctSubjects) {
  const Scene scene(Options(SubjectKind::kHuman, 3));
  ASSERT_EQ(scene.subject_count(), 3);
  const auto primitives = scene.PrimitivesAt(3.0);
  EXPECT_EQ(primitives.size(), 3u * 17u);
  EXPECT_EQ(primitives.front().subject, 0);
  EXPECT_EQ(primitives.back().subject, 2);
  EXPECT_THROW(ParseSubjectKind("robot"), InputError);
}

}  // namespace
}  // namespace silnet::sim
