#include "planeloc/sim/raycast.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace planeloc::sim {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kUnboundedArea = 4000.0;  // m^2: larger quads (the ground) skip the tree
constexpr int kBins = 12;
constexpr std::uint32_t kLeafSize = 2;

float SurfaceArea(const Eigen::AlignedBox3f& box) {
  const Eigen::Vector3f e = box.sizes();
  return 2.0f * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
}

}  // namespace

Scene::Scene(const World& world) : world_(world) {
  std::vector<Eigen::AlignedBox3f> boxes;
  std::vector<PrimRef> refs;
  for (std::size_t i = 0; i < world.quads.size(); ++i) {
    const Quad& q = world.quads[i];
    const Eigen::Vector3d eu = q.edge_u, ev = q.edge_v;
    const double uu = eu.squaredNorm(), vv = ev.squaredNorm(), uv = eu.dot(ev);
    const double det = uu * vv - uv * uv;
    QuadF f;
    f.origin = q.origin.cast<float>();
    f.normal = q.Normal().cast<float>();
    // Dual basis: a = dual_u . (p - origin), b = dual_v . (p - origin) for p on the plane.
    f.dual_u = ((vv * eu - uv * ev) / det).cast<float>();
    f.dual_v = ((uu * ev - uv * eu) / det).cast<float>();
    f.length_u = static_cast<float>(std::sqrt(uu));
    f.length_v = static_cast<float>(std::sqrt(vv));
    quads_.push_back(f);
    const PrimRef ref{PrimitiveKind::kQuad, static_cast<std::uint32_t>(i)};
    if (eu.cross(ev).norm() > kUnboundedArea) {
      unbounded_.push_back(ref);
      continue;
    }
    Eigen::AlignedBox3f box;
    for (const auto& c : q.Corners()) box.extend(c.cast<float>());
    boxes.push_back(box);
    refs.push_back(ref);
  }
  for (std::size_t i = 0; i < world.spheres.size(); ++i) {
    const Sphere& s = world.spheres[i];
    const Eigen::Vector3f c = s.center.cast<float>(), r = Eigen::Vector3f::Constant(s.radius);
    boxes.emplace_back(c - r, c + r);
    refs.push_back({PrimitiveKind::kSphere, static_cast<std::uint32_t>(i)});
  }
  for (std::size_t i = 0; i < world.cylinders.size(); ++i) {
    const Cylinder& c = world.cylinders[i];
    const Eigen::Vector3f b = c.base.cast<float>();
    const float r = static_cast<float>(c.radius);
    boxes.emplace_back(b - Eigen::Vector3f(r, r, 0),
                       b + Eigen::Vector3f(r, r, static_cast<float>(c.height)));
    refs.push_back({PrimitiveKind::kCylinder, static_cast<std::uint32_t>(i)});
  }
  if (refs.empty()) return;
  std::vector<Eigen::Vector3f> centroids;
  for (const auto& box : boxes) centroids.push_back(box.center());
  std::vector<std::uint32_t> order(refs.size());
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * refs.size());
  Build(order, 0, static_cast<std::uint32_t>(order.size()), boxes, centroids);
  prim_refs_.reserve(order.size());
  for (std::uint32_t i : order) prim_refs_.push_back(refs[i]);
}

// Binned SAH split of order[begin, end); returns the node index.
std::uint32_t Scene::Build(std::vector<std::uint32_t>& order, std::uint32_t begin,
                           std::uint32_t end, const std::vector<Eigen::AlignedBox3f>& boxes,
                           const std::vector<Eigen::Vector3f>& centroids) {
  const std::uint32_t node_index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Eigen::AlignedBox3f bounds, centroid_bounds;
  for (std::uint32_t i = begin; i < end; ++i) {
    bounds.extend(boxes[order[i]]);
    centroid_bounds.extend(centroids[order[i]]);
  }
  auto make_leaf = [&]() {
    Node& node = nodes_[node_index];
    for (int k = 0; k < 3; ++k) node.lo[k] = bounds.min()[k], node.hi[k] = bounds.max()[k];
    node.first = begin;
    node.count = end - begin;
    return node_index;
  };
  const std::uint32_t n = end - begin;
  if (n <= kLeafSize) return make_leaf();
  int axis = 0;
  centroid_bounds.sizes().maxCoeff(&axis);
  const float lo = centroid_bounds.min()[axis], extent = centroid_bounds.sizes()[axis];
  if (!(extent > 1e-6f)) return make_leaf();
  auto bin_of = [&](std::uint32_t prim) {
    const int b = static_cast<int>(kBins * (centroids[prim][axis] - lo) / extent);
    return std::clamp(b, 0, kBins - 1);
  };
  std::array<Eigen::AlignedBox3f, kBins> bin_boxes;
  std::array<int, kBins> bin_counts{};
  for (std::uint32_t i = begin; i < end; ++i) {
    const int b = bin_of(order[i]);
    bin_boxes[b].extend(boxes[order[i]]);
    ++bin_counts[b];
  }
  // Sweep: cost of splitting after bin s = area(left) * count(left) + area(right) * count(right).
  float best_cost = kInf;
  int best_split = -1;
  for (int s = 0; s < kBins - 1; ++s) {
    Eigen::AlignedBox3f left, right;
    int nl = 0, nr = 0;
    for (int b = 0; b <= s; ++b) left.extend(bin_boxes[b]), nl += bin_counts[b];
    for (int b = s + 1; b < kBins; ++b) right.extend(bin_boxes[b]), nr += bin_counts[b];
    if (nl == 0 || nr == 0) continue;
    const float cost = SurfaceArea(left) * nl + SurfaceArea(right) * nr;
    if (cost < best_cost) best_cost = cost, best_split = s;
  }
  if (best_split < 0) return make_leaf();
  const auto mid_it =
      std::stable_partition(order.begin() + begin, order.begin() + end,
                            [&](std::uint32_t p) { return bin_of(p) <= best_split; });
  const std::uint32_t mid = static_cast<std::uint32_t>(mid_it - order.begin());
  Build(order, begin, mid, boxes, centroids);
  const std::uint32_t right = Build(order, mid, end, boxes, centroids);
  Node& node = nodes_[node_index];
  for (int k = 0; k < 3; ++k) node.lo[k] = bounds.min()[k], node.hi[k] = bounds.max()[k];
  node.first = right;
  node.count = 0;
  return node_index;
}

bool Scene::HitPrimitive(const PrimRef& ref, const Eigen::Vector3f& origin,
                         const Eigen::Vector3f& dir, float t_max, Hit* hit) const {
  switch (ref.kind) {
    case PrimitiveKind::kQuad: {
      const QuadF& q = quads_[ref.index];
      const float denom = q.normal.dot(dir);
      if (std::abs(denom) < 1e-9f) return false;
      const float t = q.normal.dot(q.origin - origin) / denom;
      if (!(t > kTMin && t < t_max)) return false;
      const Eigen::Vector3f rel = origin + t * dir - q.origin;
      const float a = q.dual_u.dot(rel), b = q.dual_v.dot(rel);
      if (a < 0.0f || a > 1.0f || b < 0.0f || b > 1.0f) return false;
      hit->t = t;
      hit->normal = denom < 0.0f ? q.normal : Eigen::Vector3f(-q.normal);
      hit->uv = Eigen::Vector2f(a * q.length_u, b * q.length_v);
      break;
    }
    case PrimitiveKind::kSphere: {
      const Sphere& s = world_.spheres[ref.index];
      const Eigen::Vector3f oc = origin - s.center.cast<float>();
      const float b = oc.dot(dir), c = oc.squaredNorm() - static_cast<float>(s.radius * s.radius);
      const float disc = b * b - c;
      if (disc < 0.0f) return false;
      const float root = std::sqrt(disc);
      float t = -b - root;
      if (!(t > kTMin)) t = -b + root;
      if (!(t > kTMin && t < t_max)) return false;
      const Eigen::Vector3f n = (oc + t * dir).normalized();
      hit->t = t;
      hit->normal = n.dot(dir) < 0.0f ? n : Eigen::Vector3f(-n);
      const float r = static_cast<float>(s.radius);
      hit->uv = Eigen::Vector2f(std::atan2(n.y(), n.x()) * r,
                                std::asin(std::clamp(n.z(), -1.0f, 1.0f)) * r);
      break;
    }
    case PrimitiveKind::kCylinder: {
      const Cylinder& c = world_.cylinders[ref.index];
      const Eigen::Vector2f o2 = (origin - c.base.cast<float>()).head<2>();
      const Eigen::Vector2f d2 = dir.head<2>();
      const float a = d2.squaredNorm();
      if (a < 1e-12f) return false;
      const float b = o2.dot(d2), cc = o2.squaredNorm() - static_cast<float>(c.radius * c.radius);
      const float disc = b * b - a * cc;
      if (disc < 0.0f) return false;
      const float root = std::sqrt(disc);
      const float z0 = static_cast<float>(c.base.z()), z1 = z0 + static_cast<float>(c.height);
      bool found = false;
      for (float t : {(-b - root) / a, (-b + root) / a}) {
        const float z = origin.z() + t * dir.z();
        if (t > kTMin && t < t_max && z >= z0 && z <= z1) {
          const Eigen::Vector2f n2 = (o2 + t * d2).normalized();
          const Eigen::Vector3f n(n2.x(), n2.y(), 0.0f);
          hit->t = t;
          hit->normal = n.dot(dir) < 0.0f ? n : Eigen::Vector3f(-n);
          hit->uv =
              Eigen::Vector2f(std::atan2(n2.y(), n2.x()) * static_cast<float>(c.radius), z - z0);
          found = true;
          break;
        }
      }
      if (!found) return false;
      break;
    }
  }
  hit->kind = ref.kind;
  hit->index = ref.index;
  return true;
}

template <bool kAnyHit>
bool Scene::Traverse(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max,
                     Hit* hit, const Hit* hint) const {
  bool found = false;
  float t_best = t_max;
  Hit scratch;
  if (hint != nullptr && HitPrimitive({hint->kind, hint->index}, origin, dir, t_best, &scratch)) {
    if (kAnyHit) return true;
    *hit = scratch, t_best = scratch.t, found = true;
  }
  for (const PrimRef& ref : unbounded_) {
    if (HitPrimitive(ref, origin, dir, t_best, &scratch)) {
      if (kAnyHit) return true;
      *hit = scratch, t_best = scratch.t, found = true;
    }
  }
  if (nodes_.empty()) return found;
  // Slab test with the near/far plane of each axis chosen once per ray by the direction's sign.
  float inv[3], org[3];
  bool negative[3];
  for (int k = 0; k < 3; ++k) {
    inv[k] = 1.0f / dir[k];  // +-inf for axis-parallel rays; the slab test copes
    org[k] = origin[k];
    negative[k] = std::signbit(inv[k]);
  }
  auto enter = [&](const Node& node) {
    float t0 = kTMin, t1 = t_best;
    for (int k = 0; k < 3; ++k) {
      const float a = ((negative[k] ? node.hi[k] : node.lo[k]) - org[k]) * inv[k];
      const float b = ((negative[k] ? node.lo[k] : node.hi[k]) - org[k]) * inv[k];
      t0 = a > t0 ? a : t0;  // NaN-safe ordering (0 * inf) keeps the old bound
      t1 = b < t1 ? b : t1;
    }
    return t0 <= t1 ? t0 : kInf;
  };
  struct Entry {
    std::uint32_t node;
    float t;
  };
  Entry stack[64];
  int top = 0;
  std::uint32_t current = 0;
  if (enter(nodes_[0]) == kInf) return found;
  while (true) {
    const Node& node = nodes_[current];
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        if (HitPrimitive(prim_refs_[i], origin, dir, t_best, &scratch)) {
          if (kAnyHit) return true;
          *hit = scratch, t_best = scratch.t, found = true;
        }
      }
    } else {
      std::uint32_t near = current + 1, far = node.first;
      float t_near = enter(nodes_[near]), t_far = enter(nodes_[far]);
      if (t_far < t_near) std::swap(near, far), std::swap(t_near, t_far);
      if (t_near != kInf) {
        if (t_far != kInf && top < 64) stack[top++] = {far, t_far};
        current = near;
        continue;
      }
    }
    // Pop until a node whose entry is still in front of the best hit.
    while (top > 0 && stack[top - 1].t > t_best) --top;
    if (top == 0) return found;
    current = stack[--top].node;
  }
}

bool Scene::Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max,
                      Hit* hit, const Hit* hint) const {
  return Traverse<false>(origin, dir, t_max, hit, hint);
}

bool Scene::IntersectLinear(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max,
                            Hit* hit) const {
  bool found = false;
  Hit scratch;
  for (const auto* refs : {&unbounded_, &prim_refs_}) {
    for (const PrimRef& ref : *refs) {
      if (HitPrimitive(ref, origin, dir, t_max, &scratch))
        *hit = scratch, t_max = scratch.t, found = true;
    }
  }
  return found;
}

bool Scene::Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max) const {
  Hit scratch;
  return Traverse<true>(origin, dir, t_max, &scratch, nullptr);
}

}  // namespace planeloc::sim
