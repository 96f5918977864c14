#include "planeloc/features/keypoint_distribution.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace planeloc {
namespace {

// A node owns the corner indices order[begin, end): splitting partitions that range in place, so
// the whole distribution allocates only the node lists.
struct Node {
  cv::Rect2f box;
  int begin = 0, end = 0;
  int size() const { return end - begin; }
};

// A node can be split while it holds several corners and is wider than a pixel (corners at the
// same position would otherwise be split forever).
bool Splittable(const Node& node) {
  return node.size() > 1 && node.box.width > 1.0f && node.box.height > 1.0f;
}

// Appends the non-empty quadrants of `node` to `out` (top-left, top-right, bottom-left,
// bottom-right).
void Split(const Node& node, const std::vector<cv::KeyPoint>& corners, std::vector<int>& order,
           std::vector<Node>& out) {
  const float half_w = node.box.width / 2, half_h = node.box.height / 2;
  const float mid_x = node.box.x + half_w, mid_y = node.box.y + half_h;
  int* first = order.data() + node.begin;
  int* last = order.data() + node.end;
  int* bottom = std::partition(first, last, [&](int i) { return corners[i].pt.y < mid_y; });
  int* top_right = std::partition(first, bottom, [&](int i) { return corners[i].pt.x < mid_x; });
  int* bottom_right = std::partition(bottom, last, [&](int i) { return corners[i].pt.x < mid_x; });
  const int* bounds[5] = {first, top_right, bottom, bottom_right, last};
  for (int q = 0; q < 4; ++q) {
    if (bounds[q] == bounds[q + 1]) continue;
    Node child;
    child.box =
        cv::Rect2f(q % 2 == 0 ? node.box.x : mid_x, q < 2 ? node.box.y : mid_y, half_w, half_h);
    child.begin = static_cast<int>(bounds[q] - order.data());
    child.end = static_cast<int>(bounds[q + 1] - order.data());
    out.push_back(child);
  }
}

// Initial nodes: vertical strips about as wide as the area is high, so that nodes stay square.
std::vector<Node> InitialNodes(const std::vector<cv::KeyPoint>& corners, const cv::Rect2f& area,
                               std::vector<int>& order) {
  const int num_strips =
      std::max(1, static_cast<int>(std::lround(area.width / std::max(area.height, 1.0f))));
  const float strip_width = area.width / static_cast<float>(num_strips);
  // Counting sort of the corners by strip (stable: ascending index within a strip).
  std::vector<int> strip_of(corners.size());
  std::vector<int> first(num_strips + 1, 0);
  for (size_t i = 0; i < corners.size(); ++i) {
    strip_of[i] =
        std::clamp(static_cast<int>((corners[i].pt.x - area.x) / strip_width), 0, num_strips - 1);
    ++first[strip_of[i] + 1];
  }
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (size_t i = 0; i < corners.size(); ++i) order[fill[strip_of[i]]++] = static_cast<int>(i);
  std::vector<Node> nodes;
  for (int strip = 0; strip < num_strips; ++strip) {
    if (first[strip] == first[strip + 1]) continue;
    Node node;
    node.box = cv::Rect2f(area.x + strip * strip_width, area.y, strip_width, area.height);
    node.begin = first[strip];
    node.end = first[strip + 1];
    nodes.push_back(node);
  }
  return nodes;
}

}  // namespace

std::vector<int> DistributeQuadtree(const std::vector<cv::KeyPoint>& corners,
                                    const cv::Rect2f& area, int target) {
  std::vector<int> order(corners.size());
  std::iota(order.begin(), order.end(), 0);
  if (static_cast<int>(corners.size()) <= target) return order;
  if (target <= 0) return {};

  std::vector<Node> nodes = InitialNodes(corners, area, order);
  std::vector<Node> next;
  std::vector<int> splittable;
  while (static_cast<int>(nodes.size()) < target) {
    splittable.clear();
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
      if (Splittable(nodes[i])) splittable.push_back(i);
    }
    if (splittable.empty()) break;
    std::vector<char> split(nodes.size(), 0);
    // Each split adds up to three nodes. While that cannot overshoot the target, split everything
    // (a uniform refinement); near the target, split the most crowded nodes first so that the
    // remaining budget goes where the corners are dense.
    if (nodes.size() + 3 * splittable.size() <= static_cast<size_t>(target)) {
      for (int i : splittable) split[i] = 1;
    } else {
      std::stable_sort(splittable.begin(), splittable.end(),
                       [&](int a, int b) { return nodes[a].size() > nodes[b].size(); });
      size_t expected = nodes.size();
      for (int i : splittable) {
        split[i] = 1;
        expected += 3;  // at most; the loop re-checks with the real count
        if (expected >= static_cast<size_t>(target)) break;
      }
    }
    next.clear();
    for (size_t i = 0; i < nodes.size(); ++i) {
      if (split[i]) {
        Split(nodes[i], corners, order, next);
      } else {
        next.push_back(nodes[i]);
      }
    }
    nodes.swap(next);
  }

  // The strongest corner of each node; equal responses go to the lower index, so the result does
  // not depend on the partition order.
  std::vector<int> kept;
  kept.reserve(nodes.size());
  for (const Node& node : nodes) {
    int best = order[node.begin];
    for (int k = node.begin + 1; k < node.end; ++k) {
      const int index = order[k];
      if (corners[index].response > corners[best].response ||
          (corners[index].response == corners[best].response && index < best)) {
        best = index;
      }
    }
    kept.push_back(best);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

}  // namespace planeloc
