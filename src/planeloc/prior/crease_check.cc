#include "planeloc/prior/crease_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <set>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr float kNoDepth = std::numeric_limits<float>::infinity();

void Require(bool condition, const std::string& what) {
  if (!condition) throw OptionsError("CreaseCheckOptions." + what);
}

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// The polygon (camera frame) cut to z >= near (Sutherland-Hodgman against one plane).
std::vector<Eigen::Vector3d> ClipNear(const std::vector<Eigen::Vector3d>& polygon, double near) {
  std::vector<Eigen::Vector3d> clipped;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d& b = polygon[(i + 1) % polygon.size()];
    const bool a_in = a.z() >= near, b_in = b.z() >= near;
    if (a_in) clipped.push_back(a);
    if (a_in != b_in) clipped.push_back(a + (near - a.z()) / (b.z() - a.z()) * (b - a));
  }
  return clipped;
}

Eigen::Vector2d ProjectInCam(const StereoCamera& camera, const Eigen::Vector3d& x) {
  return {camera.fx * x.x() / x.z() + camera.cx, camera.fy * x.y() / x.z() + camera.cy};
}

bool InImage(const StereoCamera& camera, const Eigen::Vector2d& pixel) {
  return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= camera.width - 1 &&
         pixel.y() <= camera.height - 1;
}

// Cell of a level-0 pixel in the label image (clamped).
cv::Point Cell(const PlaneLabelImage& labels, const Eigen::Vector2d& pixel) {
  const int x = static_cast<int>(std::floor(pixel.x() / labels.downsample));
  const int y = static_cast<int>(std::floor(pixel.y() / labels.downsample));
  return {std::clamp(x, 0, labels.plane_id.cols - 1), std::clamp(y, 0, labels.plane_id.rows - 1)};
}

// True when the crease sample (camera frame, projecting to `pixel`) is not hidden by a nearer
// plane: its cell shows one of the crease's planes or none, or a plane not nearer than the
// sample by more than the occlusion margin (three planes meeting at a corner).
bool SampleVisible(const PlaneLabelImage& labels, const Eigen::Vector2d& pixel, double depth,
                   int plane_a, int plane_b, const CreaseCheckOptions& options) {
  const cv::Point c = Cell(labels, pixel);
  const int id = labels.IdAt(c.x, c.y);
  if (id < 0 || id == plane_a || id == plane_b) return true;
  const double label_depth = labels.depth.at<float>(c.y, c.x);
  return depth <= label_depth + options.occlusion_margin + options.occlusion_relative * depth;
}

// +1 / -1: side of the image line through a run on which `into` (3-D, from `mid`) points; 0 for
// a zero `into` or a probe that does not project.
int ImageSide(const Rigid3d& cam_from_world, const StereoCamera& camera, const Eigen::Vector3d& mid,
              const Eigen::Vector3d& into, const Eigen::Vector2d& start, const Eigen::Vector2d& end,
              double near) {
  if (into.isZero()) return 0;
  constexpr double kProbe = 0.2;  // metres
  const Eigen::Vector3d probe = cam_from_world * (mid + kProbe * into);
  if (probe.z() < near) return 0;
  const double cross = Cross(end - start, ProjectInCam(camera, probe) - start);
  return cross > 0 ? 1 : (cross < 0 ? -1 : 0);
}

double Median(std::vector<double> values) {
  auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace

void CreaseCheckOptions::Check() const {
  creases.Check();
  lsd.Check();
  Require(lsd_level >= 0, "lsd_level must be >= 0");
  Require(strip_margin_px >= 0, "strip_margin_px must be >= 0 (px)");
  Require(label_downsample >= 1, "label_downsample must be >= 1 (px)");
  Require(near_depth > 0 && max_depth > near_depth, "near_depth must be in (0, max_depth) (m)");
  Require(occlusion_margin >= 0 && occlusion_relative >= 0,
          "occlusion_margin and occlusion_relative must be >= 0");
  Require(min_visible_px > 0, "min_visible_px must be > 0 (px)");
  Require(max_angle_deg > 0 && max_angle_deg < 90, "max_angle_deg must be in (0, 90)");
  Require(confirm_px > 0 && search_px >= confirm_px, "confirm_px must be in (0, search_px] (px)");
  Require(min_overlap > 0 && min_overlap <= 1, "min_overlap must be in (0, 1]");
  Require(keep_keyframes >= 1, "keep_keyframes must be >= 1");
}

std::string CreaseCheckStats::ToJson() const {
  std::string json = fmt::format(
      "{{\"keyframe\":{},\"lsd_segments\":{},\"visible_planes\":{},\"visible_creases\":{},"
      "\"confirmed_creases\":{},\"matched_runs\":{}",
      keyframe_id, lsd_segments, visible_planes, visible_creases, confirmed_creases, matched_runs);
  if (median_edge_px) json += fmt::format(",\"median_edge_px\":{:.3f}", *median_edge_px);
  return json + fmt::format(",\"ms\":{:.3f}}}", ms);
}

PlaneLabelImage RenderPlaneLabels(const std::vector<MapPlane>& planes,
                                  const Rigid3d& cam_from_world, const StereoCamera& camera,
                                  const CreaseCheckOptions& options) {
  PlaneLabelImage labels;
  const int ds = options.label_downsample;
  labels.downsample = ds;
  const int cols = (camera.width + ds - 1) / ds, rows = (camera.height + ds - 1) / ds;
  labels.plane_id = cv::Mat(rows, cols, CV_32S, cv::Scalar(-1));
  labels.depth = cv::Mat(rows, cols, CV_32F, cv::Scalar(kNoDepth));
  cv::Mat mask(rows, cols, CV_8U);
  constexpr int kShift = 4;  // sub-cell vertices for fillPoly
  for (const MapPlane& plane : planes) {
    if (plane.polygon.size() < 3) continue;
    std::vector<Eigen::Vector3d> in_cam;
    for (const Eigen::Vector3d& p : plane.polygon) in_cam.push_back(cam_from_world * p);
    if (std::all_of(in_cam.begin(), in_cam.end(),
                    [&](const Eigen::Vector3d& x) { return x.z() > options.max_depth; })) {
      continue;
    }
    const std::vector<Eigen::Vector3d> clipped = ClipNear(in_cam, options.near_depth);
    if (clipped.size() < 3) continue;
    std::vector<cv::Point> vertices;
    for (const Eigen::Vector3d& x : clipped) {
      // Cell coordinates: cell (i, j) spans level-0 pixels [i ds, (i + 1) ds).
      const Eigen::Vector2d cell = ProjectInCam(camera, x) / ds;
      const double limit = 1e6;  // fillPoly takes ints; far-off vertices only need the direction
      vertices.emplace_back(
          static_cast<int>(std::lround(std::clamp(cell.x() - 0.5, -limit, limit) * (1 << kShift))),
          static_cast<int>(std::lround(std::clamp(cell.y() - 0.5, -limit, limit) * (1 << kShift))));
    }
    cv::Rect box = cv::boundingRect(vertices);  // in 1 << kShift units
    box = cv::Rect(cv::Point((box.x >> kShift) - 1, (box.y >> kShift) - 1),
                   cv::Point(((box.x + box.width) >> kShift) + 2,
                             ((box.y + box.height) >> kShift) + 2)) &
          cv::Rect(0, 0, cols, rows);
    if (box.empty()) continue;
    mask(box).setTo(0);
    cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{vertices}, cv::Scalar(1), cv::LINE_8,
                 kShift);
    const Plane plane_in_cam = plane.plane_in_map.Transformed(cam_from_world);
    for (int y = box.y; y < box.y + box.height; ++y) {
      const unsigned char* m = mask.ptr<unsigned char>(y);
      const double ray_y = ((y + 0.5) * ds - camera.cy) / camera.fy;
      for (int x = box.x; x < box.x + box.width; ++x) {
        if (!m[x]) continue;
        const Eigen::Vector3d ray(((x + 0.5) * ds - camera.cx) / camera.fx, ray_y, 1.0);
        const double denominator = plane_in_cam.normal.dot(ray);
        if (std::abs(denominator) < 1e-9) continue;
        const double depth = -plane_in_cam.d / denominator;
        if (depth < options.near_depth || depth > options.max_depth) continue;
        float& best = labels.depth.at<float>(y, x);
        if (depth < best) {
          best = static_cast<float>(depth);
          labels.plane_id.at<int>(y, x) = plane.id;
        }
      }
    }
  }
  return labels;
}

std::vector<ProjectedCrease> ProjectCreases(const std::vector<PlaneCrease>& creases,
                                            const PlaneLabelImage& labels,
                                            const Rigid3d& cam_from_world,
                                            const StereoCamera& camera,
                                            const CreaseCheckOptions& options) {
  constexpr double kStep = 0.05;  // metres between samples
  constexpr int kMaxSamples = 4000;
  std::vector<ProjectedCrease> runs;
  for (const PlaneCrease& crease : creases) {
    const double length = crease.Length();
    const int n = std::clamp(static_cast<int>(std::ceil(length / kStep)) + 1, 2, kMaxSamples);
    // Runs of visible samples: [first, last] sample indices.
    int first = -1;
    auto close_run = [&](int last) {
      const int begin = first;
      first = -1;
      if (begin < 0 || last <= begin) return;
      const Eigen::Vector3d a = crease.start + (crease.end - crease.start) * begin / (n - 1.0);
      const Eigen::Vector3d b = crease.start + (crease.end - crease.start) * last / (n - 1.0);
      ProjectedCrease run;
      run.crease_id = crease.id;
      run.plane_a = crease.plane_a;
      run.plane_b = crease.plane_b;
      run.start = ProjectInCam(camera, cam_from_world * a);
      run.end = ProjectInCam(camera, cam_from_world * b);
      if ((run.end - run.start).norm() < options.min_visible_px) return;
      const Eigen::Vector3d mid = 0.5 * (a + b);
      run.side_a = ImageSide(cam_from_world, camera, mid, crease.into_a, run.start, run.end,
                             options.near_depth);
      run.side_b = ImageSide(cam_from_world, camera, mid, crease.into_b, run.start, run.end,
                             options.near_depth);
      runs.push_back(run);
    };
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d x =
          cam_from_world * (crease.start + (crease.end - crease.start) * k / (n - 1.0));
      bool visible = x.z() >= options.near_depth && x.z() <= options.max_depth;
      if (visible) {
        const Eigen::Vector2d pixel = ProjectInCam(camera, x);
        visible = InImage(camera, pixel) &&
                  SampleVisible(labels, pixel, x.z(), crease.plane_a, crease.plane_b, options);
      }
      if (visible && first < 0) first = k;
      if (!visible && first >= 0) close_run(k - 1);
    }
    if (first >= 0) close_run(n - 1);
  }
  return runs;
}

void MatchCreases(const std::vector<LineSegment>& segments, const CreaseCheckOptions& options,
                  std::vector<ProjectedCrease>& runs) {
  const double cos_max_angle = std::cos(options.max_angle_deg * std::numbers::pi / 180.0);
  for (ProjectedCrease& run : runs) {
    const Eigen::Vector2d axis = run.end - run.start;
    const double length = axis.norm();
    const Eigen::Vector2d e = axis / length;
    std::optional<double> nearest;
    std::vector<std::pair<double, double>> covered;  // intervals along the run, pixels
    double offset_sum = 0, offset_weight = 0;
    for (const LineSegment& segment : segments) {
      const Eigen::Vector2d s = segment.end - segment.start;
      const double segment_length = s.norm();
      if (segment_length <= 0 || std::abs(e.dot(s)) < cos_max_angle * segment_length) continue;
      const double t0 = e.dot(segment.start - run.start), t1 = e.dot(segment.end - run.start);
      const double lo = std::max(0.0, std::min(t0, t1)), hi = std::min(length, std::max(t0, t1));
      if (hi <= lo) continue;
      const double distance = 0.5 * (std::abs(Cross(e, segment.start - run.start)) +
                                     std::abs(Cross(e, segment.end - run.start)));
      if (distance > options.search_px) continue;
      if (!nearest || distance < *nearest) nearest = distance;
      if (distance <= options.confirm_px) {
        covered.emplace_back(lo, hi);
        const double signed_offset =
            0.5 * (Cross(e, segment.start - run.start) + Cross(e, segment.end - run.start));
        offset_sum += (hi - lo) * signed_offset;
        offset_weight += hi - lo;
      }
    }
    std::sort(covered.begin(), covered.end());
    double union_length = 0, reach = 0;
    for (const auto& [lo, hi] : covered) {
      const double from = std::max(lo, reach);
      if (hi > from) union_length += hi - from;
      reach = std::max(reach, hi);
    }
    run.edge_distance_px = nearest;
    run.overlap = union_length / length;
    run.confirmed = run.overlap >= options.min_overlap;
    run.image_offset_px = offset_weight > 0 ? offset_sum / offset_weight : 0.0;
  }
}

std::vector<LineSegment> DetectSegmentsAtLevel(const cv::Mat& image, int level0_width,
                                               const LsdOptions& options) {
  const double scale = static_cast<double>(level0_width) / image.cols;
  LsdOptions at_level = options;
  at_level.min_length_px = options.min_length_px / scale;
  std::vector<LineSegment> segments = DetectLineSegments(image, at_level);
  // Pixel centres: x0 + 0.5 = (x + 0.5) * scale (as cv::resize maps them).
  for (LineSegment& segment : segments) {
    segment.start = (segment.start.array() + 0.5) * scale - 0.5;
    segment.end = (segment.end.array() + 0.5) * scale - 0.5;
    segment.width *= scale;
  }
  return segments;
}

std::vector<LineSegment> DetectSegmentsAlongRuns(const cv::Mat& image, int level0_width,
                                                 const std::vector<ProjectedCrease>& runs,
                                                 const CreaseCheckOptions& options) {
  const double to_level = static_cast<double>(image.cols) / level0_width;
  LsdOptions at_level = options.lsd;
  at_level.min_length_px = options.lsd.min_length_px * to_level;
  const double margin = options.strip_margin_px * to_level;
  const double half_height = (options.search_px + options.strip_margin_px) * to_level;
  std::vector<LineSegment> segments;
  cv::Mat strip;
  for (const ProjectedCrease& run : runs) {
    // Level pixel centres, as DetectSegmentsAtLevel maps them.
    const Eigen::Vector2d a = (run.start.array() + 0.5) * to_level - 0.5;
    const Eigen::Vector2d b = (run.end.array() + 0.5) * to_level - 0.5;
    const double length = (b - a).norm();
    if (!(length >= 1.0)) continue;
    const Eigen::Vector2d e = (b - a) / length;
    const Eigen::Vector2d n(-e.y(), e.x());
    // Strip pixel (u, v) samples the level at origin + u e + v n.
    const Eigen::Vector2d origin = a - margin * e - half_height * n;
    const cv::Size size(static_cast<int>(std::ceil(length + 2 * margin)) + 1,
                        static_cast<int>(std::ceil(2 * half_height)) + 1);
    const cv::Matx23d strip_to_level(e.x(), n.x(), origin.x(), e.y(), n.y(), origin.y());
    // Replicated borders add no edge along the image border (a constant one would).
    cv::warpAffine(image, strip, strip_to_level, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                   cv::BORDER_REPLICATE);
    for (LineSegment segment : DetectLineSegments(strip, at_level)) {
      for (Eigen::Vector2d* p : {&segment.start, &segment.end}) {
        const Eigen::Vector2d in_level = origin + p->x() * e + p->y() * n;
        *p = (in_level.array() + 0.5) / to_level - 0.5;
      }
      segment.width /= to_level;
      segments.push_back(segment);
    }
  }
  std::stable_sort(
      segments.begin(), segments.end(),
      [](const LineSegment& x, const LineSegment& y) { return x.Length() > y.Length(); });
  return segments;
}

CreaseChecker::CreaseChecker(const PlaneMap& map, const CreaseCheckOptions& options)
    : options_(options) {
  options_.Check();
  for (const MapPlane& plane : map.planes) {
    if (plane.polygon.size() < 3) continue;
    if (plane.area > 0.0 && plane.area < options_.creases.min_plane_area) continue;
    planes_.push_back(plane);
  }
  creases_ = ComputePlaneCreases(map, options_.creases);
}

CreaseCheckStats CreaseChecker::CheckKeyframe(int keyframe_id, const Rigid3d& cam_from_world,
                                              const StereoCamera& camera, const cv::Mat& image) {
  KeyframeCreaseCheck check = Compute(cam_from_world, camera, image);
  check.stats.keyframe_id = keyframe_id;
  const CreaseCheckStats stats = check.stats;
  Keep(keyframe_id, std::move(check));
  return stats;
}

KeyframeCreaseCheck CreaseChecker::Compute(const Rigid3d& cam_from_world,
                                           const StereoCamera& camera, const cv::Mat& image) const {
  const auto start = std::chrono::steady_clock::now();
  KeyframeCreaseCheck check;
  check.cam_from_world = cam_from_world;
  check.labels = RenderPlaneLabels(planes_, cam_from_world, camera, options_);
  check.runs = ProjectCreases(creases_, check.labels, cam_from_world, camera, options_);
  const std::vector<LineSegment> segments =
      options_.lsd_strips ? DetectSegmentsAlongRuns(image, camera.width, check.runs, options_)
                          : DetectSegmentsAtLevel(image, camera.width, options_.lsd);
  MatchCreases(segments, options_, check.runs);

  CreaseCheckStats& stats = check.stats;
  stats.lsd_segments = static_cast<int>(segments.size());
  std::set<int> visible_planes, visible, confirmed;
  for (int y = 0; y < check.labels.plane_id.rows; ++y) {
    for (int x = 0; x < check.labels.plane_id.cols; ++x) {
      if (check.labels.IdAt(x, y) >= 0) visible_planes.insert(check.labels.IdAt(x, y));
    }
  }
  std::vector<double> distances;
  for (const ProjectedCrease& run : check.runs) {
    visible.insert(run.crease_id);
    if (run.confirmed) confirmed.insert(run.crease_id);
    if (run.edge_distance_px) distances.push_back(*run.edge_distance_px);
  }
  stats.visible_planes = static_cast<int>(visible_planes.size());
  stats.visible_creases = static_cast<int>(visible.size());
  stats.confirmed_creases = static_cast<int>(confirmed.size());
  stats.matched_runs = static_cast<int>(distances.size());
  if (!distances.empty()) stats.median_edge_px = Median(distances);
  stats.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return check;
}

void CreaseChecker::Keep(int keyframe_id, KeyframeCreaseCheck check) {
  checks_[keyframe_id] = std::move(check);
  while (static_cast<int>(checks_.size()) > options_.keep_keyframes) checks_.erase(checks_.begin());
}

const KeyframeCreaseCheck* CreaseChecker::check(int keyframe_id) const {
  const auto it = checks_.find(keyframe_id);
  return it == checks_.end() ? nullptr : &it->second;
}

}  // namespace planeloc
