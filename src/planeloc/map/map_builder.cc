#include "planeloc/map/map_builder.h"

#include <spdlog/spdlog.h>

#include <functional>
#include <string>

#include "planeloc/io/voxel_filter.h"
#include "planeloc/map/neighborhoods.h"
#include "planeloc/util/error.h"
#include "planeloc/util/progress.h"

namespace planeloc {

void MapBuildOptions::Check() const {
  if (!(voxel_size >= 0.0)) throw OptionsError("MapBuildOptions.voxel_size must be >= 0 (m)");
  if (every < 1) throw OptionsError("MapBuildOptions.every must be >= 1");
  if (!(min_range >= 0.0)) throw OptionsError("MapBuildOptions.min_range must be >= 0 (m)");
  if (!(max_range > min_range)) {
    throw OptionsError("MapBuildOptions.max_range must be > min_range (m)");
  }
  if (buffer_points < 1000) throw OptionsError("MapBuildOptions.buffer_points must be >= 1000");
  if (!(sort_cell >= 0.0)) throw OptionsError("MapBuildOptions.sort_cell must be >= 0 (m)");
}

std::vector<Eigen::Vector3d> VoxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                             double voxel_size) {
  if (voxel_size <= 0.0 || points.empty()) return points;
  PointCloud cloud;
  cloud.points = points;
  return VoxelFilter(cloud, voxel_size).points;
}

MapAccumulator::MapAccumulator(MapBuildOptions options) : options_(std::move(options)) {
  options_.Check();
}

void MapAccumulator::AddScan(const std::vector<Eigen::Vector3d>& points_in_velo,
                             const Rigid3d& world_from_velo) {
  const double min2 = options_.min_range * options_.min_range;
  const double max2 = options_.max_range * options_.max_range;
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(points_in_velo.size());
  scan_points_ += points_in_velo.size();
  for (const auto& p : points_in_velo) {
    if (!p.allFinite()) {
      ++non_finite_points_;
      continue;
    }
    const double r2 = p.squaredNorm();
    if (r2 >= min2 && r2 <= max2) {
      kept.push_back(world_from_velo * p);
    } else {
      ++out_of_range_points_;
    }
  }
  empty_scans_ += kept.empty();
  AddPoints(std::move(kept));
  ++scans_;
}

void MapAccumulator::AddPoints(std::vector<Eigen::Vector3d> points_in_world) {
  points_in_world = VoxelDownsample(points_in_world, options_.voxel_size);
  points_.insert(points_.end(), points_in_world.begin(), points_in_world.end());
  if (points_.size() - compacted_size_ > options_.buffer_points) Compact();
}

void MapAccumulator::Compact() {
  points_ = VoxelDownsample(points_, options_.voxel_size);
  compacted_size_ = points_.size();
}

PointCloud MapAccumulator::Finish() {
  Compact();
  PointCloud map;
  if (options_.sort_cell > 0.0 && !points_.empty()) {
    const std::vector<std::int32_t> order = MortonOrder(points_, options_.sort_cell);
    map.points.resize(points_.size());
    for (std::size_t k = 0; k < order.size(); ++k) map.points[k] = points_[order[k]];
  } else {
    map.points = std::move(points_);
  }
  points_.clear();
  compacted_size_ = 0;
  return map;
}

Rigid3d CheckScanSequence(const KittiSequence& sequence, const Trajectory& poses) {
  const std::string folder = sequence.folder().string();
  CheckInput(poses.size() == sequence.size(), folder, 0,
             "the poses have " + std::to_string(poses.size()) + " entries but the sequence has " +
                 std::to_string(sequence.size()) + " frames",
             "give the pose file of this sequence (one world_from_cam per frame)");
  return sequence.RequireCamFromVelo();
}

MapBuildCounts ForEachScan(
    const MapBuildOptions& options, const KittiSequence& sequence, const Trajectory& poses,
    const std::function<void(const std::vector<Eigen::Vector3d>&, const Rigid3d&)>& sink) {
  options.Check();
  const std::string folder = sequence.folder().string();
  const Rigid3d cam_from_velo = CheckScanSequence(sequence, poses);
  MapBuildCounts counts;
  counts.frames = (sequence.size() + options.every - 1) / options.every;
  ProgressBar progress("map build", counts.frames, "scans");
  if (!options.show_progress) progress.Finish();
  for (std::size_t i = 0, done = 0; i < sequence.size(); i += options.every, ++done) {
    const auto path = sequence.velodyne_path(i);
    if (!path || !std::filesystem::exists(*path)) {
      ++counts.missing_scans;
      continue;
    }
    const VelodyneScan scan = ReadVelodyneScan(*path);
    sink(scan.points, poses.world_from_cam[i] * cam_from_velo);
    ++counts.scans;
    if (options.show_progress) progress.Update(done + 1);
  }
  progress.Finish();
  if (counts.missing_scans > 0) {
    spdlog::warn("map build: {} of {} frames have no Velodyne scan", counts.missing_scans,
                 counts.frames);
  }
  CheckInput(counts.scans > 0, folder, 0, "no Velodyne scan found in the sequence",
             "check the sequence's velodyne/ (or velodyne_points/data/) folder");
  return counts;
}

nlohmann::json MapBuildCounts::ToJson() const {
  return {{"frames", frames},
          {"missing_scans", missing_scans},
          {"scans", scans},
          {"empty_scans", empty_scans},
          {"scan_points", scan_points},
          {"non_finite_points", non_finite_points},
          {"out_of_range_points", out_of_range_points},
          {"map_points", map_points}};
}

std::optional<nlohmann::json> MapBuildCountsFromComments(const std::vector<std::string>& comments) {
  const std::string tag = kMapBuildCommentTag;
  for (const std::string& comment : comments) {
    if (comment.compare(0, tag.size(), tag) != 0) continue;
    nlohmann::json counts = nlohmann::json::parse(comment.substr(tag.size()), nullptr, false);
    if (counts.is_object()) return counts;
  }
  return std::nullopt;
}

PointCloud BuildMap(const MapBuildOptions& options, const KittiSequence& sequence,
                    const Trajectory& poses) {
  MapAccumulator accumulator(options);
  MapBuildCounts counts =
      ForEachScan(options, sequence, poses,
                  [&](const std::vector<Eigen::Vector3d>& points, const Rigid3d& world_from_velo) {
                    accumulator.AddScan(points, world_from_velo);
                  });
  PointCloud map = accumulator.Finish();
  counts.scans = accumulator.scans();
  counts.empty_scans = accumulator.empty_scans();
  counts.scan_points = accumulator.scan_points();
  counts.non_finite_points = accumulator.non_finite_points();
  counts.out_of_range_points = accumulator.out_of_range_points();
  counts.map_points = map.size();
  map.comments.push_back(kMapBuildCommentTag + counts.ToJson().dump());
  CheckInput(!map.empty(), sequence.folder().string(), 0,
             "the map is empty: no scan point lies within the range limits",
             "check --min-range / --max-range (metres)");
  spdlog::info("map build: {} scans -> {} points (voxel {} m)", accumulator.scans(), map.size(),
               options.voxel_size);
  if (accumulator.empty_scans() > 0 || accumulator.non_finite_points() > 0) {
    spdlog::warn(
        "map build: {} of the {} scans gave no point (empty, all NaN/Inf, or all beyond "
        "--min-range/--max-range); {} NaN/Inf points dropped (a damaged scan file)",
        accumulator.empty_scans(), accumulator.scans(), accumulator.non_finite_points());
  }
  return map;
}

}  // namespace planeloc
