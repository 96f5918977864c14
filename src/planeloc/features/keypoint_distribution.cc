#include "planeloc/features/keypoint_distribution.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace planeloc {
namespace {

struct Node {
  cv::Rect2f box;
  std::vector<int> keys;  // ascending indices into the corner list
};

// A node can be split while it holds several corners and is wider than a pixel (corners at the
// same position would otherwise be split forever).
bool Splittable(const Node& node) {
  return node.keys.size() > 1 && node.box.width > 1.0f && node.box.height > 1.0f;
}

// The non-empty quadrants of `node`, corners keeping their order.
std::vector<Node> Split(const Node& node, const std::vector<cv::KeyPoint>& corners) {
  const float half_w = node.box.width / 2, half_h = node.box.height / 2;
  const float mid_x = node.box.x + half_w, mid_y = node.box.y + half_h;
  std::array<Node, 4> children;
  for (int q = 0; q < 4; ++q) {
    children[q].box =
        cv::Rect2f(q % 2 == 0 ? node.box.x : mid_x, q < 2 ? node.box.y : mid_y, half_w, half_h);
  }
  for (int index : node.keys) {
    const cv::Point2f& p = corners[index].pt;
    const int q = (p.x < mid_x ? 0 : 1) + (p.y < mid_y ? 0 : 2);
    children[q].keys.push_back(index);
  }
  std::vector<Node> result;
  for (Node& child : children) {
    if (!child.keys.empty()) result.push_back(std::move(child));
  }
  return result;
}

// Initial nodes: vertical strips about as wide as the area is high, so that nodes stay square.
std::vector<Node> InitialNodes(const std::vector<cv::KeyPoint>& corners, const cv::Rect2f& area) {
  const int num_strips =
      std::max(1, static_cast<int>(std::lround(area.width / std::max(area.height, 1.0f))));
  const float strip_width = area.width / static_cast<float>(num_strips);
  std::vector<Node> strips(num_strips);
  for (int s = 0; s < num_strips; ++s) {
    strips[s].box = cv::Rect2f(area.x + s * strip_width, area.y, strip_width, area.height);
  }
  for (int i = 0; i < static_cast<int>(corners.size()); ++i) {
    const int s =
        std::clamp(static_cast<int>((corners[i].pt.x - area.x) / strip_width), 0, num_strips - 1);
    strips[s].keys.push_back(i);
  }
  std::vector<Node> nodes;
  for (Node& strip : strips) {
    if (!strip.keys.empty()) nodes.push_back(std::move(strip));
  }
  return nodes;
}

// Replaces each node flagged in `split` by its children, preserving order.
std::vector<Node> ApplySplits(std::vector<Node>& nodes, const std::vector<bool>& split,
                              const std::vector<cv::KeyPoint>& corners) {
  std::vector<Node> next;
  next.reserve(nodes.size() + 3 * nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (!split[i]) {
      next.push_back(std::move(nodes[i]));
      continue;
    }
    for (Node& child : Split(nodes[i], corners)) next.push_back(std::move(child));
  }
  return next;
}

}  // namespace

std::vector<int> DistributeQuadtree(const std::vector<cv::KeyPoint>& corners,
                                    const cv::Rect2f& area, int target) {
  std::vector<int> all(corners.size());
  std::iota(all.begin(), all.end(), 0);
  if (static_cast<int>(corners.size()) <= target) return all;
  if (target <= 0) return {};

  std::vector<Node> nodes = InitialNodes(corners, area);
  while (static_cast<int>(nodes.size()) < target) {
    std::vector<int> splittable;
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
      if (Splittable(nodes[i])) splittable.push_back(i);
    }
    if (splittable.empty()) break;
    std::vector<bool> split(nodes.size(), false);
    // Each split adds up to three nodes. While that cannot overshoot the target, split everything
    // (a uniform refinement); near the target, split the most crowded nodes first so that the
    // remaining budget goes where the corners are dense.
    if (nodes.size() + 3 * splittable.size() <= static_cast<size_t>(target)) {
      for (int i : splittable) split[i] = true;
    } else {
      std::stable_sort(splittable.begin(), splittable.end(),
                       [&](int a, int b) { return nodes[a].keys.size() > nodes[b].keys.size(); });
      size_t expected = nodes.size();
      for (int i : splittable) {
        split[i] = true;
        expected += 3;  // at most; the loop re-checks with the real count
        if (expected >= static_cast<size_t>(target)) break;
      }
    }
    nodes = ApplySplits(nodes, split, corners);
  }

  std::vector<int> kept;
  kept.reserve(nodes.size());
  for (const Node& node : nodes) {
    int best = node.keys.front();
    for (int index : node.keys) {
      if (corners[index].response > corners[best].response) best = index;
    }
    kept.push_back(best);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

}  // namespace planeloc
