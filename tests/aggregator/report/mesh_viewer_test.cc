// The report's 3D view: display copies of large meshes keep their shape, meshes are encoded
// exactly, and headless Chromium (installed by scripts/setup) loads a page with the view,
// draws the mesh with WebGL and reports no script error.

#include "aggregator/report/mesh_viewer.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>

#include "aggregator/report/display_mesh.h"
#include "aggregator/report/html_table.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

// A UV sphere of `radius` around `centre` with 2 * rings * segments triangles, outward.
TriangleMesh Sphere(const Eigen::Vector3f& centre, float radius, int rings, int segments) {
  TriangleMesh mesh;
  mesh.vertices.push_back(centre + Eigen::Vector3f(0, 0, radius));
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      mesh.vertices.push_back(
          centre + radius * Eigen::Vector3f(static_cast<float>(std::sin(theta) * std::cos(phi)),
                                            static_cast<float>(std::sin(theta) * std::sin(phi)),
                                            static_cast<float>(std::cos(theta))));
    }
  }
  mesh.vertices.push_back(centre - Eigen::Vector3f(0, 0, radius));
  const auto ring = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  const int south = static_cast<int>(mesh.vertices.size()) - 1;
  for (int s = 0; s < segments; ++s) {
    mesh.triangles.push_back({0, ring(1, s), ring(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      mesh.triangles.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      mesh.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
    mesh.triangles.push_back({ring(rings - 1, s), south, ring(rings - 1, s + 1)});
  }
  return mesh;
}

TEST(DisplayMesh, ALargeMeshIsReducedAndKeepsItsShape) {
  const Eigen::Vector3f centre(0.3f, -0.2f, 1.1f);
  const TriangleMesh sphere = Sphere(centre, 0.5f, 200, 400);  // 160 000 triangles
  const DisplayMesh small = MakeDisplayMesh(sphere, 5000);
  ASSERT_GT(small.cell, 0);
  EXPECT_LE(small.triangles.size(), 5000u);
  EXPECT_GT(small.triangles.size(), 1000u);
  ASSERT_EQ(small.normals.size(), small.positions.size());
  Eigen::AlignedBox3f box;
  size_t outward = 0;
  for (size_t v = 0; v < small.positions.size(); ++v) {
    const Eigen::Vector3f radial = small.positions[v] - centre;
    // Cluster means lie inside the sphere, within a cell's diagonal.
    EXPECT_NEAR(radial.norm(), 0.5, std::sqrt(3.0) * small.cell) << v;
    box.extend(small.positions[v]);
    EXPECT_NEAR(small.normals[v].norm(), 1.0, 1e-4) << v;
    if (small.normals[v].dot(radial.normalized()) > 0.95f) ++outward;
  }
  EXPECT_GE(outward, small.positions.size() * 98 / 100);
  EXPECT_LT((box.min() - (centre - Eigen::Vector3f::Constant(0.5f))).norm(), 2 * small.cell);
  EXPECT_LT((box.max() - (centre + Eigen::Vector3f::Constant(0.5f))).norm(), 2 * small.cell);

  const DisplayMesh same = MakeDisplayMesh(sphere, 200000);  // small enough already
  EXPECT_EQ(same.cell, 0);
  EXPECT_EQ(same.triangles.size(), sphere.triangles.size());
  EXPECT_EQ(same.positions.size(), sphere.vertices.size());
}

TEST(MeshViewer, Base64MatchesTheStandardVectors) {
  EXPECT_EQ(Base64("", 0), "");
  EXPECT_EQ(Base64("f", 1), "Zg==");
  EXPECT_EQ(Base64("fo", 2), "Zm8=");
  EXPECT_EQ(Base64("foo", 3), "Zm9v");
  EXPECT_EQ(Base64("foobar", 6), "Zm9vYmFy");
  const unsigned char high[] = {0xFF, 0xFE, 0x00};
  EXPECT_EQ(Base64(high, 3), "//4A");
}

TEST(MeshViewer, SaysWhyWithoutLibjsThree) {
  testing::TempDir dir;
  const std::string reason = InstallMeshViewer(dir.path(), dir / "no-three-here");
  EXPECT_NE(reason.find("libjs-three"), std::string::npos) << reason;
}

// The chromium binary on PATH, or empty.
std::filesystem::path Chromium() {
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    for (const char* name : {"chromium", "chromium-browser"}) {
      const std::filesystem::path candidate = std::filesystem::path(folder) / name;
      if (std::filesystem::exists(candidate)) return candidate;
    }
  }
  return {};
}

// Runs headless Chromium with software WebGL on `page` with `args` added; its exit status is
// checked, its stdout returned and its log (stderr) put in `log`.
std::string RunChromium(const std::filesystem::path& page, const std::vector<std::string>& args,
                        const std::filesystem::path& work, std::string* log) {
  std::vector<std::string> all = {"--headless",
                                  "--no-sandbox",  // CI runs as root
                                  "--disable-gpu",
                                  "--use-angle=swiftshader",
                                  "--enable-unsafe-swiftshader",
                                  "--enable-logging=stderr",
                                  "--virtual-time-budget=20000",
                                  fmt::format("--user-data-dir={}", (work / "profile").string())};
  all.insert(all.end(), args.begin(), args.end());
  all.push_back("file://" + page.string());
  testing::ChildProcess chromium(Chromium(), all, work);
  const std::optional<int> status = chromium.Wait(std::chrono::seconds(180));
  EXPECT_EQ(status, std::optional<int>(0)) << chromium.Stderr();
  *log = chromium.Stderr();
  return chromium.Stdout();
}

TEST(MeshViewer, HeadlessChromiumDrawsTheMeshWithoutScriptErrors) {
  const std::filesystem::path chromium = Chromium();
  ASSERT_FALSE(chromium.empty()) << "chromium is not installed: scripts/setup installs it";
  testing::TempDir dir;
  ASSERT_EQ(InstallMeshViewer(dir.path()), "");
  const DisplayMesh sphere = MakeDisplayMesh(Sphere({0, 0, 1}, 0.4f, 40, 80));
  WriteViewerMesh(dir.path(), "sphere", sphere);
  WriteViewerMesh(dir.path(), "shell", MakeDisplayMesh(Sphere({0, 0, 1}, 0.5f, 10, 20)));
  ViewerLayer shell{"shell", "shell", 0x6fa8dc, true, false};
  const std::filesystem::path page = dir / "page.html";
  WriteHtmlPage(page, "viewer test",
                MeshViewerHtml("view", {ViewerLayer{"sphere", "a <sphere>"}, shell}));

  std::string log;
  const std::string dom = RunChromium(page, {"--dump-dom"}, dir.path(), &log);
  std::smatch state;
  ASSERT_TRUE(std::regex_search(dom, state, std::regex("data-viewer-state=\"([^\"]*)\"")))
      << dom.substr(0, 2000);
  EXPECT_EQ(state[1].str(), fmt::format("drawn {} triangles", sphere.triangles.size()));
  EXPECT_NE(dom.find("a &lt;sphere&gt;"), std::string::npos);
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
  EXPECT_EQ(log.find(":CONSOLE("), std::string::npos) << log;  // nothing logged by the page

  // A sequence shows its first frame only, behind a slider.
  const std::filesystem::path sequence_page = dir / "sequence.html";
  WriteHtmlPage(
      sequence_page, "sequence test",
      MeshViewerHtml("frames", {ViewerLayer{"shell", "frame 1"}, ViewerLayer{"sphere", "frame 2"}},
                     std::nullopt, true));
  const std::string sequence_dom = RunChromium(sequence_page, {"--dump-dom"}, dir.path(), &log);
  ASSERT_TRUE(std::regex_search(sequence_dom, state, std::regex("data-viewer-state=\"([^\"]*)\"")));
  EXPECT_EQ(state[1].str(),
            fmt::format("drawn {} triangles",
                        MakeDisplayMesh(Sphere({0, 0, 1}, 0.5f, 10, 20)).triangles.size()));
  EXPECT_NE(sequence_dom.find("class=\"viewer-sequence\""), std::string::npos);

  // The canvas shows the sphere: the model's colour around the middle of the view.
  RunChromium(
      page, {"--window-size=1000,700", fmt::format("--screenshot={}", (dir / "shot.png").string())},
      dir.path(), &log);
  const cv::Mat shot = cv::imread((dir / "shot.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(shot.empty());
  int model = 0, background = 0;
  for (int y = 0; y < std::min(shot.rows, 560); ++y) {
    for (int x = 0; x < std::min(shot.cols, 960); ++x) {
      const cv::Vec3b bgr = shot.at<cv::Vec3b>(y, x);
      if (bgr[2] > bgr[0] + 15 && bgr[2] > 60) ++model;  // warm: red above blue
      if (bgr[0] == 0x2b && bgr[1] == 0x2b && bgr[2] == 0x2b) ++background;
    }
  }
  EXPECT_GT(model, 5000);
  EXPECT_GT(background, 50000);
}

}  // namespace
}  // namespace silnet::aggregator
