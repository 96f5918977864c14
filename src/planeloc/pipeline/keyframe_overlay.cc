#include "planeloc/pipeline/keyframe_overlay.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

#include "planeloc/features/line_segments.h"
#include "planeloc/features/orb_extractor.h"
#include "planeloc/features/stereo_matcher.h"
#include "planeloc/prior/crease_check.h"

namespace planeloc {
namespace {

// A distinct, stable colour per plane id (golden-ratio hues), BGR.
cv::Vec3b PlaneColor(int id) {
  const double hue = std::fmod(0.13 + 0.61803398875 * id, 1.0) * 180.0;
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 200, 255));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  return bgr.at<cv::Vec3b>(0, 0);
}

// Tints the image by the plane seen at each pixel and draws the planes' outlines.
void TintPlanes(const PlaneLabelImage& labels, cv::Mat& image, KeyframeOverlayCounts& n) {
  if (labels.plane_id.empty()) return;
  const int ds = std::max(1, labels.downsample);
  cv::Mat tint = image.clone();
  std::map<int, bool> seen;
  for (int y = 0; y < image.rows; ++y) {
    const int cy = std::min(y / ds, labels.plane_id.rows - 1);
    for (int x = 0; x < image.cols; ++x) {
      const int cx = std::min(x / ds, labels.plane_id.cols - 1);
      const int id = labels.IdAt(cx, cy);
      if (id < 0) continue;
      seen[id] = true;
      tint.at<cv::Vec3b>(y, x) = PlaneColor(id);
    }
  }
  n.planes_in_view = static_cast<int>(seen.size());
  cv::addWeighted(image, 0.72, tint, 0.28, 0, image);
  // Outlines: cells whose right or lower neighbour shows another plane (or none).
  for (int cy = 0; cy < labels.plane_id.rows; ++cy) {
    for (int cx = 0; cx < labels.plane_id.cols; ++cx) {
      const int id = labels.IdAt(cx, cy);
      const int right_id = cx + 1 < labels.plane_id.cols ? labels.IdAt(cx + 1, cy) : id;
      const int down_id = cy + 1 < labels.plane_id.rows ? labels.IdAt(cx, cy + 1) : id;
      if (id == right_id && id == down_id) continue;
      const int owner = id >= 0 ? id : std::max(right_id, down_id);
      if (owner < 0) continue;
      const cv::Vec3b c = PlaneColor(owner);
      cv::rectangle(image, cv::Rect(cx * ds, cy * ds, ds, ds), cv::Scalar(c[0], c[1], c[2]),
                    cv::FILLED);
    }
  }
}

// The left image's features: on a plane (stereo depth within the plane's band) in its colour,
// the others grey.
void DrawFeatures(const cv::Mat& left, const cv::Mat& right, const StereoCamera& camera,
                  const Rigid3d& world_from_cam, const PlaneLabelImage& labels,
                  const std::map<int, const MapPlane*>& planes_by_id, const TrackerOptions& options,
                  cv::Mat& image, KeyframeOverlayCounts& n) {
  const int ds = std::max(1, labels.downsample);
  const OrbExtractor extractor(options.orb);
  const StereoFeatures features =
      ExtractStereoFeatures(left, right, camera, extractor, options.stereo);
  n.features = static_cast<int>(features.left.keypoints.size());
  for (std::size_t k = 0; k < features.left.keypoints.size(); ++k) {
    const cv::Point2f& p = features.left.keypoints[k].pt;
    const double z = features.depth[k];
    int plane_id = -1;
    if (z > 0) {
      ++n.with_depth;
      const int cx = static_cast<int>(p.x) / ds, cy = static_cast<int>(p.y) / ds;
      if (!labels.plane_id.empty() && cx >= 0 && cy >= 0 && cx < labels.plane_id.cols &&
          cy < labels.plane_id.rows) {
        const int id = labels.IdAt(cx, cy);
        const auto it = planes_by_id.find(id);
        if (it != planes_by_id.end()) {
          const Eigen::Vector3d in_cam((p.x - camera.cx) / camera.fx * z,
                                       (p.y - camera.cy) / camera.fy * z, z);
          const Eigen::Vector3d in_world = world_from_cam * in_cam;
          const double distance = std::abs(it->second->plane_in_map.SignedDistance(in_world));
          if (distance <= std::max(0.25, 0.02 * z)) plane_id = id;
        }
      }
    }
    if (plane_id >= 0) {
      ++n.on_planes;
      const cv::Vec3b c = PlaneColor(plane_id);
      cv::circle(image, p, 3, cv::Scalar(c[0], c[1], c[2]), cv::FILLED, cv::LINE_AA);
      cv::circle(image, p, 3, cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
    } else {
      cv::circle(image, p, 2, cv::Scalar(150, 150, 150), 1, cv::LINE_AA);
    }
  }
}

void DrawCaption(bool with_map, const KeyframeOverlayCounts& n, cv::Mat& image) {
  const std::string caption =
      with_map ? fmt::format(
                     "{} features, {} with depth, {} on planes | {} LSD segments | {} planes "
                     "in view",
                     n.features, n.with_depth, n.on_planes, n.segments, n.planes_in_view)
               : fmt::format("{} features, {} with depth | {} LSD segments (no plane map)",
                             n.features, n.with_depth, n.segments);
  cv::rectangle(image, cv::Rect(0, 0, image.cols, 22), cv::Scalar(20, 20, 20), cv::FILLED);
  cv::putText(image, caption, cv::Point(8, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
}

}  // namespace

cv::Mat DrawKeyframeOverlay(const cv::Mat& left, const cv::Mat& right, const StereoCamera& camera,
                            const Rigid3d& world_from_cam, const PlaneMap* map,
                            const TrackerOptions& options, KeyframeOverlayCounts* counts) {
  KeyframeOverlayCounts local;
  KeyframeOverlayCounts& n = counts ? *counts : local;
  n = {};
  cv::Mat image;
  cv::cvtColor(left, image, cv::COLOR_GRAY2BGR);
  image.convertTo(image, -1, 0.7, 0);  // darker, so the drawing stands out

  // Plane regions: the crease check's label image, finer cells for a smoother outline.
  const Rigid3d cam_from_world = world_from_cam.Inverse();
  std::map<int, const MapPlane*> planes_by_id;
  PlaneLabelImage labels;
  if (map != nullptr) {
    for (const MapPlane& plane : map->planes) planes_by_id[plane.id] = &plane;
    CreaseCheckOptions crease = options.planes.crease;
    crease.label_downsample = 2;
    labels = RenderPlaneLabels(map->planes, cam_from_world, camera, crease);
  }
  TintPlanes(labels, image, n);

  const std::vector<LineSegment> segments = DetectLineSegments(left, options.planes.crease.lsd);
  n.segments = static_cast<int>(segments.size());
  for (const LineSegment& s : segments) {
    cv::line(image, cv::Point2d(s.start.x(), s.start.y()), cv::Point2d(s.end.x(), s.end.y()),
             cv::Scalar(245, 245, 245), 1, cv::LINE_AA);
  }

  DrawFeatures(left, right, camera, world_from_cam, labels, planes_by_id, options, image, n);
  DrawCaption(map != nullptr, n, image);
  return image;
}

}  // namespace planeloc
