// silnet-sim: simulated camera networks with ground truth.
//   silnet-sim generate -o DIR [options]   write a dataset folder (masks, frames, ground truth)
//   silnet-sim stills -o DIR [options]     stereo stills of a statue with the true surface
//   silnet-sim run-nodes DIR [options]     a live silnet-node per camera of the dataset

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>

#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"
#include "shared/util/log.h"
#include "sim/dataset_generator.h"
#include "sim/node_launcher.h"
#include "sim/stills_generator.h"

namespace {

using silnet::InputError;

// Parses "640x480".
std::pair<int, int> ParseSize(const std::string& text) {
  static const std::regex pattern(R"((\d{2,5})x(\d{2,5}))");
  std::smatch match;
  if (!std::regex_match(text, match, pattern)) {
    throw InputError("image size must look like 640x480, not '" + text + "'");
  }
  return {std::stoi(match[1]), std::stoi(match[2])};
}

int RunGenerate(const silnet::sim::SimulationOptions& base, const std::string& output,
                const std::string& size, const std::string& layout, const std::string& subject,
                uint64_t seed) {
  silnet::sim::SimulationOptions options = base;
  std::tie(options.network.width, options.network.height) = ParseSize(size);
  options.network.layout = silnet::sim::ParseRigLayout(layout);
  options.scene.subject = silnet::sim::ParseSubjectKind(subject);
  options.network.seed = seed;
  options.scene.seed = seed;
  options.render.seed = seed;
  if (options.scene.subject == silnet::sim::SubjectKind::kStatue ||
      options.scene.subject == silnet::sim::SubjectKind::kStillsStatue) {
    options.scene.walk_radius = 0.0;
  }
  const size_t tasks =
      static_cast<size_t>(options.network.cameras) * static_cast<size_t>(options.frames);
  silnet::Progress progress("sim", tasks, silnet::ConsoleProgressPrinter(),
                            std::chrono::seconds(2));
  spdlog::info("rendering {} cameras x {} frames ({}x{}, {} layout, {} subject, seed {}) into {}",
               options.network.cameras, options.frames, options.network.width,
               options.network.height, layout, subject, seed, output);
  const auto summary = silnet::sim::GenerateDataset(options, output, &progress);
  std::printf("wrote %zu images (%.1f MB) for %zu cameras x %d frames in %.1f s\n",
              summary.images_written, static_cast<double>(summary.bytes_written) / 1e6,
              summary.cameras.size(), summary.frames, summary.seconds);
  std::printf("ground truth: %s/ground_truth.yaml\n", output.c_str());
  for (const auto& c : summary.cameras) {
    std::printf("  %s  f=%.1f px  centre=(%.2f, %.2f, %.2f) m  fps=%.3f  offset=%+.3f frames\n",
                c.id.c_str(), c.K(0, 0), c.Center().x(), c.Center().y(), c.Center().z(), c.fps,
                c.time_offset);
  }
  return 0;
}

int RunStills(silnet::sim::StillsOptions options, const std::string& output,
              const std::string& size, const std::string& layout, const std::string& cameras_from,
              double scale) {
  std::tie(options.network.width, options.network.height) = ParseSize(size);
  options.network.layout = silnet::sim::ParseRigLayout(layout);
  if (!cameras_from.empty()) {
    // A live dataset's cameras at the still resolution: what its nodes' still streams see.
    if (!(scale > 0.0 && scale <= 8.0)) throw InputError("--scale must lie in (0, 8]");
    for (const silnet::CameraModel& c :
         silnet::LoadCalibration(std::filesystem::path(cameras_from) / "ground_truth.yaml")) {
      options.cameras.push_back(
          silnet::CameraAtImageSize(c, static_cast<int>(std::lround(c.width * scale)),
                                    static_cast<int>(std::lround(c.height * scale))));
    }
  }
  silnet::Progress progress("stills",
                            options.cameras.empty() ? static_cast<size_t>(options.network.cameras)
                                                    : options.cameras.size(),
                            silnet::ConsoleProgressPrinter(), std::chrono::seconds(2));
  if (options.cameras.empty()) {
    spdlog::info(
        "rendering stills of the statue from {} cameras ({}x{}, {} layout, seed {}) into {}",
        options.network.cameras, options.network.width, options.network.height, layout,
        options.seed, output);
  } else {
    spdlog::info(
        "rendering stills of the statue from the {} cameras of {} ({}x{}, seed {}) into {}",
        options.cameras.size(), cameras_from, options.cameras.front().width,
        options.cameras.front().height, options.seed, output);
  }
  const auto summary = silnet::sim::GenerateStills(options, output, &progress);
  std::printf("wrote %zu images and %zu surface points (%.1f MB) for %zu cameras in %.1f s\n",
              summary.images_written, summary.surface_points,
              static_cast<double>(summary.bytes_written) / 1e6, summary.cameras.size(),
              summary.seconds);
  std::printf("cameras at %.2f m; pixel footprint at the statue %.2f mm; surface spacing %.2f mm\n",
              summary.radius, 1e3 * summary.footprint, 1e3 * summary.surface_spacing);
  std::printf("stills:       %s/<camera>/stills/000000.png, masks/000000.png\n", output.c_str());
  std::printf("calibration:  %s/calibration.yaml\n", output.c_str());
  std::printf("ground truth: %s/ground_truth.yaml, %s/gt_surface.ply\n", output.c_str(),
              output.c_str());
  return 0;
}

// silnet-node beside this program in a build tree (build/sim/silnet-sim ->
// build/node/silnet-node) or in the same folder (an installation).
std::filesystem::path DefaultNodeBinary() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return "silnet-node";
  const std::filesystem::path beside = self.parent_path() / "silnet-node";
  if (std::filesystem::exists(beside)) return beside;
  return self.parent_path().parent_path() / "node" / "silnet-node";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"silnet-sim: simulated camera networks with ground truth"};
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");

  silnet::sim::SimulationOptions options;
  std::string output, size = "640x480", layout = "ring", subject = "human";
  uint64_t seed = 1;
  bool masks_only = false, frames_only = false, no_shadows = false, steady_light = false;
  CLI::App* generate = app.add_subcommand("generate", "write a simulated dataset folder");
  generate->add_option("-o,--out", output, "output folder")->required();
  generate->add_option("--cameras", options.network.cameras, "number of cameras")
      ->capture_default_str();
  generate->add_option("--layout", layout, "ring, dome or arc")->capture_default_str();
  generate->add_option("--frames", options.frames, "frames per camera")->capture_default_str();
  generate->add_option("--fps", options.network.fps, "nominal frame rate")->capture_default_str();
  generate
      ->add_option("--fps-spread", options.network.fps_spread,
                   "relative spread of per-camera frame rates")
      ->capture_default_str();
  generate->add_option("--size", size, "image size WxH")->capture_default_str();
  generate
      ->add_option("--fov", options.network.horizontal_fov_deg,
                   "nominal horizontal field of view, degrees")
      ->capture_default_str();
  generate->add_option("--radius", options.network.radius, "camera distance from centre, m")
      ->capture_default_str();
  generate
      ->add_option("--max-offset", options.network.max_offset,
                   "time offsets uniform in +-this many frames")
      ->capture_default_str();
  generate
      ->add_option("--distortion", options.network.max_distortion,
                   "largest |k1| of radial distortion (0 = none)")
      ->capture_default_str();
  generate
      ->add_option("--principal-spread", options.network.principal_spread,
                   "principal points up to this fraction of the image size off centre")
      ->capture_default_str();
  generate->add_option("--noise", options.render.noise_sigma, "sensor noise sigma, DN")
      ->capture_default_str();
  generate->add_option("--subject", subject, "human, quadruped, statue or stills-statue")
      ->capture_default_str();
  generate->add_option("--subjects", options.scene.count, "number of subjects")
      ->capture_default_str();
  generate
      ->add_option("--walk-radius", options.scene.walk_radius,
                   "subjects stay within this distance of the centre, m")
      ->capture_default_str();
  generate->add_option("--seed", seed, "random seed (same seed, same bytes)")
      ->capture_default_str();
  generate->add_option("--threads", options.threads, "render threads (0 = all cores)")
      ->capture_default_str();
  generate->add_flag("--masks-only", masks_only, "write silhouettes only");
  generate->add_flag("--frames-only", frames_only, "write colour frames only");
  generate->add_flag("--no-shadows", no_shadows, "do not cast shadows");
  generate->add_flag("--steady-light", steady_light, "no lighting changes");
  generate->add_flag("--force", options.overwrite, "write into a non-empty folder");
  std::vector<std::string> moves;
  generate->add_option("--move-camera", moves,
                       "knock a camera out of place: cam03@560:2.5[:0.05] pans cam03 by 2.5 deg "
                       "at frame 560 (and shifts it 0.05 m sideways); repeatable");

  silnet::sim::StillsOptions stills_options;
  std::string stills_output, stills_size = "640x480", stills_layout = "ring";
  CLI::App* stills = app.add_subcommand(
      "stills", "render stereo stills of a statue with ground truth (the true surface)");
  stills->add_option("-o,--out", stills_output, "output folder")->required();
  stills->add_option("--cameras", stills_options.network.cameras, "number of cameras")
      ->capture_default_str();
  stills->add_option("--layout", stills_layout, "ring or dome")->capture_default_str();
  stills->add_option("--size", stills_size, "image size WxH")->capture_default_str();
  stills
      ->add_option("--fov", stills_options.network.horizontal_fov_deg,
                   "nominal horizontal field of view, degrees")
      ->capture_default_str();
  stills
      ->add_option("--radius", stills_options.radius,
                   "camera distance from the statue, m (0 = from --fill)")
      ->capture_default_str();
  stills
      ->add_option("--fill", stills_options.fill,
                   "share of the image height the statue fills (sets the distance)")
      ->capture_default_str();
  stills
      ->add_option("--distortion", stills_options.network.max_distortion,
                   "largest |k1| of radial distortion (0 = none)")
      ->capture_default_str();
  stills->add_option("--noise", stills_options.render.noise_sigma, "sensor noise sigma, DN")
      ->capture_default_str();
  stills
      ->add_option("--spacing", stills_options.surface_spacing,
                   "gt_surface.ply point spacing, m (0 = half the pixel footprint)")
      ->capture_default_str();
  stills->add_option("--seed", stills_options.seed, "random seed (same seed, same bytes)")
      ->capture_default_str();
  stills->add_option("--threads", stills_options.threads, "render threads (0 = all cores)")
      ->capture_default_str();
  stills->add_flag("--backgrounds", stills_options.write_backgrounds,
                   "also write <camera>/background.png, the empty room");
  stills->add_flag("--force", stills_options.overwrite, "write into a non-empty folder");
  std::string stills_cameras_from;
  double stills_scale = 1.0;
  stills->add_option(
      "--cameras-from", stills_cameras_from,
      "use the cameras of this `generate` dataset instead of a new ring or dome "
      "(write into <dataset>/statue: its nodes' still streams then show the statue)");
  stills
      ->add_option("--scale", stills_scale,
                   "with --cameras-from: the stills' resolution relative to the dataset's")
      ->capture_default_str();

  silnet::sim::NodeLaunchOptions nodes;
  std::string node_binary;
  CLI::App* run_nodes =
      app.add_subcommand("run-nodes", "start a live silnet-node per camera of a dataset");
  run_nodes->add_option("dataset", nodes.dataset, "dataset folder from `generate`")->required();
  run_nodes->add_option("--node", node_binary, "the silnet-node program (default: the build's)");
  run_nodes->add_option("--logs", nodes.log_dir,
                        "folder for the nodes' logs (default: beside "
                        "the dataset, node-logs/)");
  run_nodes->add_option("--speed", nodes.speed, "replay speed (1 = the cameras' frame rates)")
      ->capture_default_str();
  run_nodes->add_flag("--masks", nodes.masks, "replay masks instead of segmenting colour frames");
  run_nodes->add_option("--linger", nodes.linger_s, "seconds nodes stay after their feed ends")
      ->capture_default_str();
  run_nodes->add_option("--start-delay", nodes.start_delay_s, "seconds until the common start")
      ->capture_default_str();
  run_nodes->add_option("--node-arg", nodes.extra_args, "an argument for every node (repeatable)");

  CLI11_PARSE(app, argc, argv);
  try {
    silnet::ConfigureLogging("silnet-sim", log_level);
    if (masks_only && frames_only)
      throw InputError("--masks-only and --frames-only exclude each other");
    options.write_frames = !masks_only;
    options.write_masks = !frames_only;
    options.render.shadows = !no_shadows;
    options.scene.lighting_changes = !steady_light;
    for (const std::string& m : moves)
      options.moves.push_back(silnet::sim::ParseCameraMove(m, options.network.cameras));
    if (generate->parsed()) return RunGenerate(options, output, size, layout, subject, seed);
    if (stills->parsed()) {
      if (stills_layout != "ring" && stills_layout != "dome")
        throw InputError("stills take a ring or a dome of cameras, not '" + stills_layout + "'");
      return RunStills(stills_options, stills_output, stills_size, stills_layout,
                       stills_cameras_from, stills_scale);
    }
    if (run_nodes->parsed()) {
      nodes.node_binary =
          node_binary.empty() ? DefaultNodeBinary() : std::filesystem::path(node_binary);
      if (nodes.log_dir.empty()) nodes.log_dir = nodes.dataset.parent_path() / "node-logs";
      const int failed = silnet::sim::RunNodes(nodes);
      if (failed > 0) std::fprintf(stderr, "silnet-sim: %d node(s) failed\n", failed);
      return failed > 0 ? 1 : 0;
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "silnet-sim: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "silnet-sim: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
