// silnet-sim's stereo stills: the layout the stereo job reads, determinism per seed,
// silhouettes consistent with the true surface, the statue's through-hole and thin staff,
// and gt_surface.ply's points on the outer surface with outward normals.

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "shared/io/calibration_yaml.h"
#include "shared/io/point_cloud_ply.h"
#include "shared/util/check.h"
#include "sim/render/camera_renderer.h"
#include "sim/scene/outer_surface.h"
#include "sim/scene/scene.h"
#include "sim/stills_generator.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet::sim {
namespace {

const std::filesystem::path kSim = std::filesystem::path(SILNET_BINARY_DIR) / "sim/silnet-sim";

std::string ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<Primitive> StatuePrimitives(uint64_t seed = 1) {
  SceneOptions options;
  options.subject = SubjectKind::kStillsStatue;
  options.walk_radius = 0.0;
  options.seed = seed;
  return Scene(options).PrimitivesAt(0.0);
}

// Background components of a 0/255 mask that do not touch the image border, as pixel lists.
std::vector<std::vector<cv::Point>> EnclosedBackground(const cv::Mat& mask) {
  cv::Mat labels;
  const int count = cv::connectedComponents(mask == 0, labels, 4);
  std::vector<bool> at_border(static_cast<size_t>(count), false);
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      if (y == 0 || x == 0 || y == labels.rows - 1 || x == labels.cols - 1) {
        at_border[static_cast<size_t>(labels.at<int>(y, x))] = true;
      }
    }
  }
  std::vector<std::vector<cv::Point>> holes(static_cast<size_t>(count));
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      const int label = labels.at<int>(y, x);
      if (mask.at<uint8_t>(y, x) == 0 && !at_border[static_cast<size_t>(label)]) {
        holes[static_cast<size_t>(label)].push_back({x, y});
      }
    }
  }
  std::erase_if(holes, [](const auto& h) { return h.empty(); });
  return holes;
}

// One default stills folder (16 cameras, ring, 640x480) shared by the tests below.
class DefaultStills : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new silnet::testing::TempDir("silnet-stills");
    StillsOptions options;
    options.threads = 2;
    summary_ = new StillsSummary(GenerateStills(options, dir_->path() / "ring", nullptr));
  }
  static void TearDownTestSuite() {
    delete summary_;
    delete dir_;
  }
  static std::filesystem::path Root() { return dir_->path() / "ring"; }

  static silnet::testing::TempDir* dir_;
  static StillsSummary* summary_;
};
silnet::testing::TempDir* DefaultStills::dir_ = nullptr;
StillsSummary* DefaultStills::summary_ = nullptr;

TEST_F(DefaultStills, WritesTheStereoLayoutWithCalibrationAndGroundTruth) {
  const auto cameras = LoadCalibration(Root() / "calibration.yaml");
  ASSERT_EQ(cameras.size(), 16u);
  const auto truth_cameras = LoadCalibration(Root() / "ground_truth.yaml");
  ASSERT_EQ(truth_cameras.size(), 16u);
  for (size_t i = 0; i < cameras.size(); ++i) {
    const CameraModel& c = cameras[i];
    EXPECT_EQ(c.id, truth_cameras[i].id);
    EXPECT_LT((c.R - truth_cameras[i].R).norm(), 1e-9);
    EXPECT_EQ(c.width, 640);
    EXPECT_EQ(c.height, 480);
    EXPECT_FALSE(c.HasDistortion());
    ASSERT_GT(std::filesystem::file_size(StillPath(Root(), c.id)), 10000u) << c.id;
    ASSERT_GT(std::filesystem::file_size(StillMaskPath(Root(), c.id)), 500u) << c.id;
    const cv::Mat still = cv::imread(StillPath(Root(), c.id).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat mask = cv::imread(StillMaskPath(Root(), c.id).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(still.type(), CV_8UC3);
    ASSERT_EQ(mask.type(), CV_8UC1);
    EXPECT_EQ(still.size(), cv::Size(640, 480));
    EXPECT_EQ(mask.size(), cv::Size(640, 480));
    EXPECT_EQ(cv::countNonZero(mask == 0) + cv::countNonZero(mask == 255), 640 * 480) << c.id;
    // The statue is whole in the picture and fills a good part of its height.
    const cv::Rect box = cv::boundingRect(mask);
    EXPECT_GT(box.x, 0);
    EXPECT_GT(box.y, 0);
    EXPECT_LT(box.br().x, 640);
    EXPECT_LT(box.br().y, 480);
    EXPECT_GE(box.height, 0.6 * 480) << c.id;
    EXPECT_LE(box.height, 0.9 * 480) << c.id;
  }
  const OrientedPointCloud cloud = ReadPointCloudPly(Root() / "gt_surface.ply");
  EXPECT_EQ(cloud.points.size(), summary_->surface_points);
  EXPECT_GT(cloud.points.size(), 100000u);
  EXPECT_NEAR(summary_->surface_spacing, 0.5 * summary_->footprint, 1e-12);
  EXPECT_GT(summary_->footprint, 0.004);
  EXPECT_LT(summary_->footprint, 0.008);
}

TEST_F(DefaultStills, EverySurfacePointProjectsIntoEverySilhouette) {
  const auto cameras = LoadCalibration(Root() / "calibration.yaml");
  const OrientedPointCloud cloud = ReadPointCloudPly(Root() / "gt_surface.ply");
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<size_t> pick(0, cloud.points.size() - 1);
  std::vector<Eigen::Vector3d> sample;
  for (int i = 0; i < 20000; ++i)
    sample.push_back(cloud.points[pick(rng)].cast<double>());
  for (const CameraModel& c : cameras) {
    const cv::Mat mask = cv::imread(StillMaskPath(Root(), c.id).string(), cv::IMREAD_GRAYSCALE);
    cv::Mat dilated;
    cv::dilate(mask, dilated, cv::Mat::ones(3, 3, CV_8U));
    size_t inside = 0;
    for (const Eigen::Vector3d& X : sample) {
      const auto pixel = c.Project(X);
      if (!pixel) continue;
      const int x = static_cast<int>(std::lround(pixel->x()));
      const int y = static_cast<int>(std::lround(pixel->y()));
      if (x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && dilated.at<uint8_t>(y, x) != 0) {
        ++inside;
      }
    }
    EXPECT_GE(static_cast<double>(inside), 0.995 * static_cast<double>(sample.size())) << c.id;
  }
}

TEST_F(DefaultStills, SomeViewsSeeThroughTheArmLoopAndTheirRaysThereMissTheStatue) {
  const auto cameras = LoadCalibration(Root() / "calibration.yaml");
  const std::vector<Primitive> statue = StatuePrimitives();
  int views_with_hole = 0;
  for (const CameraModel& c : cameras) {
    const cv::Mat mask = cv::imread(StillMaskPath(Root(), c.id).string(), cv::IMREAD_GRAYSCALE);
    for (const auto& hole : EnclosedBackground(mask)) {
      if (hole.size() < 30) continue;
      ++views_with_hole;
      // Every ray through the hole passes the statue.
      for (const cv::Point& p : hole) {
        const Eigen::Vector3d dir = c.R.transpose() * c.PixelRay({p.x, p.y}).normalized();
        for (const Primitive& primitive : statue) {
          double t = 0.0;
          ASSERT_FALSE(primitive.Intersect(c.Center(), dir, &t)) << c.id << " " << p;
        }
      }
      break;
    }
  }
  // The loop is open from the front and the back of a 16-camera ring, at least.
  EXPECT_GE(views_with_hole, 2);
}

TEST_F(DefaultStills, TheStaffAndTheForwardArmCrossTheBodysOutlineInSomeViews) {
  const auto cameras = LoadCalibration(Root() / "calibration.yaml");
  SceneOptions options;
  options.subject = SubjectKind::kStillsStatue;
  const Scene scene(options);
  const std::vector<Primitive> statue = scene.PrimitivesAt(0.0);
  const auto& names = scene.subject(0).PartNames();
  auto parts = [&](auto keep) {
    std::vector<Primitive> out;
    for (const Primitive& p : statue) {
      if (keep(names[static_cast<size_t>(p.part)])) out.push_back(p);
    }
    return out;
  };
  const auto staff = parts([](const std::string& n) { return n == "staff"; });
  const auto body = parts([](const std::string& n) { return n != "staff" && n != "right_hand"; });
  const auto forearm = parts([](const std::string& n) { return n == "right_forearm"; });
  const auto chest = parts([](const std::string& n) { return n == "chest"; });
  // A part whose silhouette lies partly on and partly off another's crosses its outline:
  // the union's outline has T-junctions there.
  auto crosses = [](const cv::Mat& a, const cv::Mat& b) {
    return cv::countNonZero(a & b) >= 20 && cv::countNonZero(a & ~b) >= 20;
  };
  int staff_views = 0, arm_views = 0;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const CameraRenderer renderer(cameras[i], scene, RenderSettings{}, static_cast<int>(i));
    cv::Mat a, b, c, d;
    renderer.RenderPrimitives(staff, 1.0, 0, &a, nullptr);
    renderer.RenderPrimitives(body, 1.0, 0, &b, nullptr);
    renderer.RenderPrimitives(forearm, 1.0, 0, &c, nullptr);
    renderer.RenderPrimitives(chest, 1.0, 0, &d, nullptr);
    staff_views += crosses(a, b) ? 1 : 0;
    arm_views += crosses(c, d) ? 1 : 0;
  }
  // Of 16 views around the statue, the staff crosses in 8 and the forearm in 5.
  EXPECT_GE(staff_views, 4);
  EXPECT_GE(arm_views, 3);
}

TEST_F(DefaultStills, SurfaceNormalsPointOutwards) {
  const OrientedPointCloud cloud = ReadPointCloudPly(Root() / "gt_surface.ply");
  const std::vector<Primitive> statue = StatuePrimitives();
  size_t outside_ahead = 0, inside_behind = 0, unit = 0, checked = 0;
  for (size_t i = 0; i < cloud.points.size(); i += 7) {
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    const Eigen::Vector3d n = cloud.normals[i].cast<double>();
    if (std::abs(n.norm() - 1.0) < 1e-5) ++unit;
    if (!AnyContains(statue, p + 0.002 * n)) ++outside_ahead;
    if (AnyContains(statue, p - 0.002 * n)) ++inside_behind;
    ++checked;
  }
  EXPECT_EQ(unit, checked);
  EXPECT_EQ(inside_behind, checked);
  // Near the creases where primitives meet, a step along the normal may enter a neighbour.
  EXPECT_GE(static_cast<double>(outside_ahead), 0.99 * static_cast<double>(checked));
}

TEST(StillsStatue, ArmLoopTouchesTheBodyOnlyAtItsEndsAndTheStaffIsThin) {
  SceneOptions options;
  options.subject = SubjectKind::kStillsStatue;
  const Scene scene(options);
  const std::vector<Primitive> statue = scene.PrimitivesAt(0.0);
  const auto& names = scene.subject(0).PartNames();
  auto part = [&](const std::string& name) -> const Primitive& {
    for (const Primitive& p : statue) {
      if (names[static_cast<size_t>(p.part)] == name) return p;
    }
    throw std::runtime_error("no part " + name);
  };
  const Primitive& staff = part("staff");
  EXPECT_LE(staff.radius, 0.015);
  EXPECT_GE((staff.b - staff.a).norm(), 1.8);
  // The middle of each arm segment keeps 1 cm clear of chest, pelvis and hand.
  std::mt19937_64 rng(2);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const char* arm : {"left_upper_arm", "left_forearm"}) {
    const Primitive& a = part(arm);
    for (double s = 0.2; s <= 0.8; s += 0.05) {
      const Eigen::Vector3d axis = a.a + s * (a.b - a.a);
      for (int k = 0; k < 200; ++k) {
        const Eigen::Vector3d u =
            Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
        const Eigen::Vector3d x = axis + (a.radius + 0.01) * u;
        for (const char* body : {"chest", "pelvis", "left_hand"}) {
          ASSERT_FALSE(part(body).Contains(x)) << arm << " at " << s << " touches " << body;
        }
      }
    }
  }
  // ... while the loop is closed: arm and hand overlap, and hand and pelvis.
  const Primitive& hand = part("left_hand");
  auto overlaps = [&](const Primitive& p, const Primitive& q) {
    std::mt19937_64 r(3);
    for (const Eigen::Vector3d& x : SampleSurfaceUniformly(p, 4000, r)) {
      if (q.Contains(x)) return true;
    }
    return false;
  };
  EXPECT_TRUE(overlaps(hand, part("pelvis")));
  EXPECT_TRUE(overlaps(part("left_forearm"), hand));
  EXPECT_TRUE(overlaps(part("left_upper_arm"), part("chest")));
  // The staff touches nothing but the fist.
  for (const Primitive& p : statue) {
    if (&p == &staff) continue;
    EXPECT_EQ(overlaps(staff, p), names[static_cast<size_t>(p.part)] == "right_hand")
        << names[static_cast<size_t>(p.part)];
  }
}

TEST(OuterSurface, SamplesAreUniformByAreaAndHiddenPartsAreLeftOut) {
  const Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  const Primitive capsule =
      Primitive::MakeCapsule({0, 0, 0}, {0, 0, 0.4}, 0.05, frame, 0, 0);  // side : caps = 4 : 1
  std::mt19937_64 rng(1);
  size_t on_side = 0;
  const auto points = SampleSurfaceUniformly(capsule, 20000, rng);
  for (const Eigen::Vector3d& p : points) {
    EXPECT_NEAR((p - Eigen::Vector3d(0, 0, std::clamp(p.z(), 0.0, 0.4))).norm(), 0.05, 1e-9);
    if (p.z() > 0.0 && p.z() < 0.4) ++on_side;
  }
  EXPECT_NEAR(static_cast<double>(on_side) / 20000.0, 0.8, 0.01);
  // An ellipsoid: the count per area as asked for, and the share near one tip as its area's.
  const Primitive ellipsoid = Primitive::MakeEllipsoid({0, 0, 0}, {0.3, 0.05, 0.1}, frame, 0, 0);
  const auto e = SampleOuterSurface({ellipsoid}, 0.003, 2);
  EXPECT_NEAR(static_cast<double>(e.size()), ellipsoid.SurfaceArea() / 0.003 / 0.003, 1.0);
  const double tips = static_cast<double>(std::count_if(
      e.begin(), e.end(), [](const SurfacePoint& s) { return s.position.x() > 0.15; }));
  // Area with x > 0.15 of this ellipsoid, by a fine triangulation: 20.1 % of the total.
  EXPECT_NEAR(tips / static_cast<double>(e.size()), 0.201, 0.01);
  // Two overlapping spheres: no sample inside the other one.
  const Primitive a = Primitive::MakeEllipsoid({0, 0, 0}, {0.1, 0.1, 0.1}, frame, 0, 0);
  const Primitive b = Primitive::MakeEllipsoid({0.1, 0, 0}, {0.1, 0.1, 0.1}, frame, 0, 0);
  const auto union_points = SampleOuterSurface({a, b}, 0.004, 3);
  for (const SurfacePoint& s : union_points) {
    EXPECT_FALSE(a.Contains(s.position) && b.Contains(s.position));
  }
  // Each sphere loses a cap of area 2 pi r h with h = r/2: a quarter; the union keeps 3/4.
  EXPECT_NEAR(static_cast<double>(union_points.size()),
              2.0 * 0.75 * a.SurfaceArea() / 0.004 / 0.004, 200.0);
}

TEST(Stills, SameSeedSameBytesThroughTheCommandLineAnotherSeedDiffers) {
  silnet::testing::TempDir dir;
  silnet::testing::ChildProcess sim(
      kSim,
      {"stills", "-o", (dir / "cli").string(), "--cameras", "6", "--layout", "dome", "--size",
       "320x240", "--seed", "3", "--threads", "2", "--backgrounds"},
      dir.path());
  ASSERT_EQ(sim.Wait(std::chrono::seconds(60)), std::optional<int>(0)) << sim.Stderr();
  EXPECT_NE(sim.Stdout().find("gt_surface.ply"), std::string::npos) << sim.Stdout();
  StillsOptions options;
  options.network.cameras = 6;
  options.network.layout = RigLayout::kDome;
  options.network.width = 320;
  options.network.height = 240;
  options.seed = 3;
  options.threads = 1;
  options.write_backgrounds = true;
  GenerateStills(options, dir / "same", nullptr);
  options.seed = 4;
  GenerateStills(options, dir / "other", nullptr);
  size_t compared = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir / "cli")) {
    if (!entry.is_regular_file()) continue;
    const auto relative = std::filesystem::relative(entry.path(), dir / "cli");
    ASSERT_EQ(ReadBytes(entry.path()), ReadBytes(dir / "same" / relative)) << relative;
    ++compared;
  }
  EXPECT_EQ(compared, 6u * 3u + 3u);
  // The background is the still without the statue (and its shadow): apart from noise, the
  // two differ where the mask is set.
  const cv::Mat still = cv::imread(StillPath(dir / "cli", "cam01").string());
  const cv::Mat background = cv::imread(BackgroundPath(dir / "cli", "cam01").string());
  const cv::Mat mask = cv::imread(StillMaskPath(dir / "cli", "cam01").string(), 0);
  cv::Mat difference;
  cv::absdiff(still, background, difference);
  cv::cvtColor(difference, difference, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::mean(difference, mask)[0], 20.0);
  EXPECT_LT(cv::mean(difference, mask == 0)[0], 5.0);
  EXPECT_NE(ReadBytes(dir / "cli/cam00/stills/000000.png"),
            ReadBytes(dir / "other/cam00/stills/000000.png"));
  EXPECT_NE(ReadBytes(dir / "cli/calibration.yaml"), ReadBytes(dir / "other/calibration.yaml"));
}

TEST(Stills, BadOptionsFailWithAClearMessage) {
  silnet::testing::TempDir dir;
  StillsOptions options;
  options.fill = 2.0;
  EXPECT_THROW(GenerateStills(options, dir / "a", nullptr), InputError);
  options = StillsOptions();
  options.network.cameras = 6;
  options.network.width = options.network.height = 64;
  GenerateStills(options, dir / "b", nullptr);
  EXPECT_THROW(GenerateStills(options, dir / "b", nullptr), InputError);  // not empty
  options.overwrite = true;
  EXPECT_NO_THROW(GenerateStills(options, dir / "b", nullptr));
  silnet::testing::ChildProcess sim(kSim, {"stills", "-o", (dir / "c").string(), "--layout", "arc"},
                                    dir.path());
  ASSERT_EQ(sim.Wait(std::chrono::seconds(30)), std::optional<int>(2));
  EXPECT_NE(sim.Stderr().find("ring or a dome"), std::string::npos) << sim.Stderr();
}

}  // namespace
}  // namespace silnet::sim
