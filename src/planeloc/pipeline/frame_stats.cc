#include "planeloc/pipeline/frame_stats.h"

#include <fmt/format.h>

namespace planeloc {

const char* TrackingStateName(TrackingState state) {
  switch (state) {
    case TrackingState::kTracking:
      return "tracking";
    case TrackingState::kLost:
      return "lost";
    case TrackingState::kRelocalized:
      return "relocalized";
  }
  return "unknown";
}

std::string FrameStats::ToJson() const {
  std::string json = fmt::format(
      "{{\"frame\":{},\"state\":\"{}\",\"skipped\":{},\"features\":{},\"stereo_matches\":{},"
      "\"tracked_points\":{},\"inliers\":{},\"keyframe\":{},\"ms\":{{\"extract\":{:.3f},"
      "\"track\":{:.3f},\"local_map\":{:.3f},\"ba\":{:.3f}}}",
      frame, TrackingStateName(state), skipped ? "true" : "false", features, stereo_matches,
      tracked_points, inliers, keyframe ? "true" : "false", ms_extract, ms_track, ms_local_map,
      ms_ba);
  if (keyframe_id) json += fmt::format(",\"keyframe_id\":{}", *keyframe_id);
  if (ba_median_reprojection_px) {
    json += fmt::format(",\"ba_median_reprojection_px\":{:.4f}", *ba_median_reprojection_px);
  }
  if (ba_plane_residuals) json += fmt::format(",\"ba_plane_residuals\":{}", *ba_plane_residuals);
  if (ba_window_keyframes) {
    json += fmt::format(",\"ba_window_keyframes\":{}", *ba_window_keyframes);
  }
  if (ba_fixed_keyframes) {
    json += fmt::format(",\"ba_fixed_keyframes\":{}", *ba_fixed_keyframes);
  }
  if (ba_discarded) json += ",\"ba_discarded\":true";
  if (ba_keyframe) json += fmt::format(",\"ba_keyframe\":{}", *ba_keyframe);
  if (!map_lock.empty()) json += fmt::format(",\"map_lock\":\"{}\"", map_lock);
  if (registration) json += ",\"registration\":" + *registration;
  if (planes_disabled) json += fmt::format(",\"planes_disabled\":{}", *planes_disabled);
  if (depth_points) json += fmt::format(",\"depth_points\":{}", *depth_points);
  if (depth_residual_px) json += fmt::format(",\"depth_residual_px\":{:.3f}", *depth_residual_px);
  if (depth_refused) json += ",\"depth_refused\":true";
  if (consensus_correction) {
    json +=
        fmt::format(",\"consensus_correction\":[{:.4f},{:.4f},{:.4f}]", consensus_correction->x(),
                    consensus_correction->y(), consensus_correction->z());
  }
  if (latency_ms) json += fmt::format(",\"latency_ms\":{:.2f}", *latency_ms);
  if (crease_check) json += ",\"crease_check\":" + crease_check->ToJson();
  return json + "}";
}

std::string BaCounts::ToJson() const {
  return fmt::format(
      "{{\"keyframes\":{},\"applied\":{},\"superseded\":{},\"discarded\":{},\"unusable\":{},"
      "\"empty\":{},\"stale_keyframes\":{},\"stale_points\":{},\"culled_keyframes\":{},"
      "\"forgotten_keyframes\":{}}}",
      keyframes, applied, superseded, discarded, unusable, empty, stale_keyframes, stale_points,
      culled_keyframes, forgotten_keyframes);
}

}  // namespace planeloc
