#include "shared/io/calibration_yaml.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <map>

#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

std::vector<CameraModel> TwoCameras() {
  std::vector<CameraModel> cameras(2);
  for (int i = 0; i < 2; ++i) {
    CameraModel& c = cameras[static_cast<size_t>(i)];
    c.id = "cam0" + std::to_string(i);
    c.width = 640;
    c.height = 480;
    c.K << 512.25 + i, 0, 320.5, 0, 511.75, 239.125, 0, 0, 1;
    c.dist << 0.05 * i, -0.01, 0.001, -0.002, 0.0;
    c.R = Eigen::AngleAxisd(0.4 + i, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    c.t = Eigen::Vector3d(0.1, -0.2, 4.0 + i);
    c.fps = 29.97;
    c.time_offset = -3.5 + 7.25 * i;
  }
  return cameras;
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST(CalibrationYaml, RoundTripsEveryField) {
  testing::TempDir dir;
  const auto cameras = TwoCameras();
  SaveCalibration(dir / "calibration.yaml", cameras);
  const auto loaded = LoadCalibration(dir / "calibration.yaml");
  ASSERT_EQ(loaded.size(), cameras.size());
  for (size_t i = 0; i < cameras.size(); ++i) {
    EXPECT_EQ(loaded[i].id, cameras[i].id);
    EXPECT_EQ(loaded[i].width, 640);
    EXPECT_EQ(loaded[i].height, 480);
    EXPECT_LT((loaded[i].K - cameras[i].K).norm(), 1e-12);
    EXPECT_LT((loaded[i].dist - cameras[i].dist).norm(), 1e-12);
    EXPECT_LT((loaded[i].R - cameras[i].R).norm(), 1e-12);
    EXPECT_LT((loaded[i].t - cameras[i].t).norm(), 1e-12);
    EXPECT_DOUBLE_EQ(loaded[i].fps, 29.97);
    EXPECT_DOUBLE_EQ(loaded[i].time_offset, cameras[i].time_offset);
  }
}

// Expects LoadCalibration to throw InputError whose message contains `fragment`.
void ExpectRejected(const std::filesystem::path& path, const std::string& fragment) {
  EXPECT_THAT([&] { LoadCalibration(path); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(fragment)))
      << path;
}

TEST(CalibrationYaml, RejectsMissingAndMalformedFilesWithReasons) {
  testing::TempDir dir;
  ExpectRejected(dir / "absent.yaml", "no such file");
  WriteText(dir / "garbage.yaml", "%YAML:1.0\n---\ncameras: [ {id: a, image_width: [1,2\n");
  ExpectRejected(dir / "garbage.yaml", "garbage.yaml");
  WriteText(dir / "empty.yaml", "%YAML:1.0\n---\nsomething: 1\n");
  ExpectRejected(dir / "empty.yaml", "no 'cameras'");

  // A valid camera, then one field broken at a time.
  auto camera_file = [&](const std::string& field, const std::string& value) {
    std::map<std::string, std::string> fields = {
        {"id", "cam00"},
        {"image_width", "640"},
        {"image_height", "480"},
        {"K",
         "!!opencv-matrix { rows: 3, cols: 3, dt: d, data: [500, 0, 320, 0, 500, 240, 0, 0, 1] }"},
        {"dist", "!!opencv-matrix { rows: 1, cols: 5, dt: d, data: [0, 0, 0, 0, 0] }"},
        {"R", "!!opencv-matrix { rows: 3, cols: 3, dt: d, data: [1, 0, 0, 0, 1, 0, 0, 0, 1] }"},
        {"t", "!!opencv-matrix { rows: 3, cols: 1, dt: d, data: [0, 0, 4] }"}};
    if (value.empty()) {
      fields.erase(field);
    } else {
      fields[field] = value;
    }
    std::string text = "%YAML:1.0\n---\ncameras:\n  - {";
    for (const auto& [key, text_value] : fields)
      text += " " + key + ": " + text_value + ",";
    text.back() = ' ';
    text += "}\n";
    WriteText(dir / "camera.yaml", text);
    return dir / "camera.yaml";
  };
  EXPECT_EQ(LoadCalibration(camera_file("id", "cam00")).size(), 1u);
  ExpectRejected(camera_file("image_width", "-640"), "image_width");
  ExpectRejected(camera_file("id", ""), "missing 'id'");
  ExpectRejected(camera_file("id", "\"\""), "'id' is empty");
  ExpectRejected(
      camera_file("K", "!!opencv-matrix { rows: 2, cols: 3, dt: d, data: [1, 0, 0, 0, 1, 0] }"),
      "'K' has 6 entries");
  ExpectRejected(
      camera_file(
          "K",
          "!!opencv-matrix { rows: 3, cols: 3, dt: d, data: [0, 0, 320, 0, 500, 240, 0, 0, 1] }"),
      "positive focal");
  ExpectRejected(camera_file("t", ""), "missing 't'");
  ExpectRejected(camera_file("R", "[1, 2, 3]"), "'R'");
  // A declared size is refused before OpenCV allocates it (80 GB here).
  ExpectRejected(
      camera_file("K", "!!opencv-matrix { rows: 100000, cols: 100000, dt: d, data: [1] }"),
      "'K' has 10000000000 entries, expected 9");
  ExpectRejected(camera_file("K",
                             "!!opencv-matrix { rows: 3, cols: 3, dt: \"2d\", data: [1, 2, 3, 4, "
                             "5, 6, 7, 8, 9, 1, 2, 3, 4, 5, 6, 7, 8, 9] }"),
                 "'K' is not a matrix (more than one channel)");
  ExpectRejected(camera_file("fps", ".Inf"), "fps must be positive");
  ExpectRejected(camera_file("time_offset", ".NaN"), "time_offset must be finite");
  ExpectRejected(camera_file("time_offset", "soon"), "'time_offset' must be a number");
  WriteText(dir / "scalars.yaml", "%YAML:1.0\n---\ncameras: [ 1, 2 ]\n");
  ExpectRejected(dir / "scalars.yaml", "camera 0: not a map of fields");
}

TEST(CalibrationYaml, RejectsTwoCamerasWithOneId) {
  testing::TempDir dir;
  auto cameras = TwoCameras();
  cameras[1].id = cameras[0].id;
  SaveCalibration(dir / "c.yaml", cameras);
  ExpectRejected(dir / "c.yaml", "camera 1 ('cam00'): a second camera with this id");
}

// OpenCV 4.6's parser loops forever on this 24-byte file (found by the input_file fuzz
// target) and crashes on deep nesting: both are tried in a child process and refused.
TEST(CalibrationYaml, RefusesFilesTheParserLoopsOnOrCrashesOn) {
  const std::string loops = "%YAML:1.0\n    K: r\n-  -\n ";
  const std::string problem = YamlParserProblem(loops, std::chrono::milliseconds(300));
  EXPECT_NE(problem.find("does not finish on it (stopped after 0.3 s)"), std::string::npos)
      << problem;
  const std::string crashes =
      "%YAML:1.0\n---\ncameras: " + std::string(200000, '[') + std::string(200000, ']') + "\n";
  EXPECT_NE(YamlParserProblem(crashes, kYamlParseLimit).find("crashes on it (signal"),
            std::string::npos);
  // Valid and invalid files the parser answers: no problem.
  EXPECT_EQ(YamlParserProblem("%YAML:1.0\n---\na: [1, 2]\n", kYamlParseLimit), "");
  EXPECT_EQ(YamlParserProblem("%YAML:1.0\n---\na: [1, 2\n", kYamlParseLimit), "");

  testing::TempDir dir;
  WriteText(dir / "loops.yaml", loops);
  EXPECT_THAT([&] { OpenYamlForReading(dir / "loops.yaml", std::chrono::milliseconds(300)); },
              ::testing::ThrowsMessage<InputError>(
                  ::testing::HasSubstr("not a silnet file: OpenCV's YAML parser does not finish")));
}

// OpenCV's parser recurses once per nesting level: without the guard these files of a few
// hundred kilobytes overflow the stack and kill the process.
TEST(CalibrationYaml, RefusesNestingThatWouldOverflowTheParser) {
  testing::TempDir dir;
  const std::string header = "%YAML:1.0\n---\n";
  WriteText(dir / "brackets.yaml",
            header + "cameras: " + std::string(200000, '[') + std::string(200000, ']') + "\n");
  ExpectRejected(dir / "brackets.yaml", "nests '[' and '{' more than 256 deep (line 3)");
  std::string dashes = header + "cameras: []\nother:\n";
  for (int k = 0; k < 100000; ++k)
    dashes += "- ";
  WriteText(dir / "dashes.yaml", dashes + "1\n");
  ExpectRejected(dir / "dashes.yaml", "line 5 is indented or nested in sequences more than");
  // Nesting within the limits still reads.
  auto cameras = TwoCameras();
  SaveCalibration(dir / "c.yaml", cameras);
  std::ifstream in(dir / "c.yaml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  WriteText(dir / "nested.yaml",
            text + "extra: " + std::string(200, '[') + std::string(200, ']') + "\n");
  EXPECT_EQ(LoadCalibration(dir / "nested.yaml").size(), 2u);
}

TEST(CalibrationYaml, RejectsANonRotation) {
  testing::TempDir dir;
  auto cameras = TwoCameras();
  cameras[1].R(0, 0) += 0.1;
  SaveCalibration(dir / "c.yaml", cameras);
  ExpectRejected(dir / "c.yaml", "not a rotation");
  cameras = TwoCameras();
  cameras[1].R = -cameras[1].R;
  SaveCalibration(dir / "c.yaml", cameras);
  ExpectRejected(dir / "c.yaml", "not a rotation");
}

// A calibration written by another tool with its rotations to four decimals is read, each R
// the rotation nearest to what was written (the reader used to refuse anything not
// orthonormal to 1e-6).
TEST(CalibrationYaml, TakesRotationsPrintedToFourDecimals) {
  testing::TempDir dir;
  auto cameras = TwoCameras();
  const auto truth = cameras;
  for (CameraModel& c : cameras)
    c.R = (c.R * 1e4).array().round() / 1e4;
  ASSERT_GT((cameras[1].R * cameras[1].R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-6);
  SaveCalibration(dir / "c.yaml", cameras);
  const auto loaded = LoadCalibration(dir / "c.yaml");
  ASSERT_EQ(loaded.size(), 2u);
  for (size_t i = 0; i < loaded.size(); ++i) {
    EXPECT_LT((loaded[i].R * loaded[i].R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(loaded[i].R.determinant(), 1.0, 1e-12);
    EXPECT_LT((loaded[i].R - truth[i].R).cwiseAbs().maxCoeff(), 1e-4);
  }
}

TEST(CalibrationYaml, CamerasAtAFrameApplyTheMovesUpToIt) {
  testing::TempDir dir;
  const auto cameras = TwoCameras();
  CameraModel moved = cameras[1];
  moved.t += Eigen::Vector3d(0.3, 0.0, 0.0);
  CameraModel moved_again = moved;
  moved_again.t += Eigen::Vector3d(0.0, 0.2, 0.0);
  {
    cv::FileStorage fs((dir / "truth.yaml").string(), cv::FileStorage::WRITE);
    WriteCameras(fs, cameras);
    WriteCameraMoves(fs, {{90, moved_again}, {40, moved}});  // any order
  }
  EXPECT_EQ(LoadCamerasAtFrame(dir / "truth.yaml", 39)[1].t, cameras[1].t);
  EXPECT_EQ(LoadCamerasAtFrame(dir / "truth.yaml", 40)[1].t, moved.t);
  EXPECT_EQ(LoadCamerasAtFrame(dir / "truth.yaml", 1000)[1].t, moved_again.t);
  EXPECT_EQ(LoadCamerasAtFrame(dir / "truth.yaml", 1000)[0].t, cameras[0].t);
  EXPECT_EQ(LoadCalibration(dir / "truth.yaml")[1].t, cameras[1].t);

  CameraModel stranger = moved;
  stranger.id = "cam07";
  {
    cv::FileStorage fs((dir / "bad.yaml").string(), cv::FileStorage::WRITE);
    WriteCameras(fs, cameras);
    WriteCameraMoves(fs, {{10, stranger}});
  }
  EXPECT_THAT([&] { LoadCamerasAtFrame(dir / "bad.yaml", 20); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("unknown camera cam07")));
}

}  // namespace
}  // namespace silnet
