// The simulator's `tiny` drives shared by the pipeline's whole-sequence test suites
// (pipeline.slow): each seed is rendered once per test process, and its LiDAR map and clean plane
// map are made once, when a suite first asks for them. Rendering and the map were most of these
// suites' time, and every suite made them with the same defaults (the preset as it is,
// MapBuildOptions without progress, MapPlanesOptions()), so sharing changes no result. The
// drive's folder is read-only to the suites: they write their runs into folders of their own.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/map_planes.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::testing {

struct TinyDrive {
  std::filesystem::path dir;  // sim/ and, once made, planes.json
  sim::SimResult sim;
  std::unique_ptr<PointCloud> map;   // the scans at the GT poses (BuildMap)
  std::unique_ptr<PlaneMap> planes;  // RunMapPlanes on `map`, also written to dir/planes.json
};

// `seed`: the preset's default when empty.
inline TinyDrive& SharedTinyDrive(std::optional<int> seed = std::nullopt) {
  // Declared first, destroyed last: the drives' folders go with it at exit.
  static TempDir root("planeloc-tiny-drives");
  static std::map<std::optional<int>, std::unique_ptr<TinyDrive>> drives;
  std::unique_ptr<TinyDrive>& drive = drives[seed];
  if (!drive) {
    drive = std::make_unique<TinyDrive>();
    drive->dir = root.path() / (seed ? "seed_" + std::to_string(*seed) : std::string("default"));
    sim::SimOptions options = sim::SimOptions::FromPreset("tiny");
    if (seed) options.seed = *seed;
    options.show_progress = false;
    drive->sim = sim::GenerateSequence(options, drive->dir / "sim");
  }
  return *drive;
}

inline const sim::SimResult& SharedTinySim(std::optional<int> seed = std::nullopt) {
  return SharedTinyDrive(seed).sim;
}

inline const PointCloud& SharedTinyMap(std::optional<int> seed = std::nullopt) {
  TinyDrive& drive = SharedTinyDrive(seed);
  if (!drive.map) {
    MapBuildOptions build;
    build.show_progress = false;
    drive.map =
        std::make_unique<PointCloud>(BuildMap(build, KittiSequence::Open(drive.sim.sequence_dir),
                                              ReadKittiTrajectory(drive.sim.poses_path)));
  }
  return *drive.map;
}

inline const PlaneMap& SharedTinyPlanes(std::optional<int> seed = std::nullopt) {
  TinyDrive& drive = SharedTinyDrive(seed);
  if (!drive.planes) {
    drive.planes = std::make_unique<PlaneMap>(
        RunMapPlanes(SharedTinyMap(seed), MapPlanesOptions()).extraction.plane_map);
    WritePlaneMap(drive.dir / "planes.json", *drive.planes);
  }
  return *drive.planes;
}

// The clean plane map's planes.json.
inline std::filesystem::path SharedTinyPlanesPath(std::optional<int> seed = std::nullopt) {
  SharedTinyPlanes(seed);
  return SharedTinyDrive(seed).dir / "planes.json";
}

}  // namespace planeloc::testing
