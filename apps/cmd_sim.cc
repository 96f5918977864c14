// `planeloc sim`: generate a synthetic urban stereo + LiDAR sequence in the KITTI odometry layout
// with ground-truth poses and planes (see docs/sim.md).
#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "command_registry.h"
#include "flags.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/error.h"

namespace planeloc::cli {
namespace {

struct SimArgs {
  std::string out;
  std::string preset = "small";
  std::uint32_t seed = 1;
  std::optional<int> frames;
  std::string lighting = "constant";
  std::string texture_dir;
  std::string trajectory;
  std::optional<std::string> changes;
  bool force = false;
};

int Run(const SimArgs& args) {
  if (args.frames) {
    CheckFlag(*args.frames >= 1, "--frames", *args.frames, "a frame count >= 1",
              "e.g. --frames 20, or leave it out for the preset's length");
  }
  sim::SimOptions options;
  options.preset = args.preset;
  options.seed = args.seed;
  options.frames = args.frames;
  options.lighting = sim::ParseLighting(args.lighting);
  options.texture_dir = args.texture_dir;
  options.trajectory_path = args.trajectory;
  if (args.changes) options.changes = sim::ParseWorldChanges(*args.changes);
  const auto start = std::chrono::steady_clock::now();
  const sim::SimResult result = sim::GenerateSequence(options, args.out, args.force);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("sim: {} frames ({} preset, seed {}, {} lighting) in {:.1f} s -> {}", result.frames,
               options.preset, options.seed, args.lighting, seconds, args.out);
  spdlog::info("sim: sequence {}, poses {}, GT planes {}", result.sequence_dir.string(),
               result.poses_path.string(), result.planes_path.string());
  if (options.changes.Any()) {
    spdlog::info(
        "sim: changes {}: the LiDAR scans the mapping-time world, the cameras the world "
        "now (labels in {}, counts in world/README.txt)",
        options.changes.ToSpec(), result.planes_path.string());
  }
  return 0;
}

const CommandRegistrar kRegistrar("sim", [](CLI::App& app) -> CommandRunner {
  auto args = std::make_shared<SimArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sim", "Synthetic town: stereo images, LiDAR scans, GT poses and planes (KITTI layout)");
  cmd->add_option("--out", args->out, "Output folder (KITTI odometry layout)")->required();
  cmd->add_option("--preset", args->preset,
                  "tiny | small | kitti07-like | rural (country road) | room (indoor, ASL layout)")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "Seed of the town, motion and noise")
      ->capture_default_str();
  cmd->add_option("--frames", args->frames, "Number of frames (default: the preset's)");
  cmd->add_option("--lighting", args->lighting, "constant | changing")
      ->check(CLI::IsMember({"constant", "changing"}))
      ->capture_default_str();
  cmd->add_option("--texture-dir", args->texture_dir, "Folder of facade images (png/jpg)");
  cmd->add_option("--trajectory", args->trajectory,
                  "KITTI pose file to drive along (e.g. poses/07.txt); --frames takes the first N");
  cmd->add_option("--changes", args->changes,
                  "World changed since the LiDAR map: renovation | none | "
                  "moved=F,offset=MIN:MAX,removed=N,new=N,cars=N (docs/sim.md)");
  cmd->add_flag("--force", args->force, "Overwrite the simulator's files in a non-empty --out");
  return [args] { return Run(*args); };
});

}  // namespace
}  // namespace planeloc::cli
