// Ray casting against a World: the primitives converted to float, a bounding volume hierarchy
// (binned SAH, flattened, near-child-first traversal) for closest-hit and any-hit queries.
// Immutable after construction, so any number of threads may query it at once.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "planeloc/sim/world.h"

namespace planeloc::sim {

enum class PrimitiveKind : std::uint8_t { kQuad, kSphere, kCylinder };

struct Hit {
  float t = 0.0f;  // ray parameter (metres for a unit direction)
  PrimitiveKind kind = PrimitiveKind::kQuad;
  std::uint32_t index = 0;  // into World::quads / spheres / cylinders
  Eigen::Vector3f normal;   // unit, facing the ray origin
  Eigen::Vector2f uv;       // surface coordinates in metres (see world.h)
};

class Scene {
 public:
  explicit Scene(const World& world);

  // Closest hit with t in (t_min, t_max); false when the ray escapes. `dir` must be unit length.
  // `hint` (e.g. the neighbouring pixel's hit) is tested first: a tight bound early prunes most
  // of the tree for coherent rays; the result is the same closest hit (ties aside).
  bool Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max, Hit* hit,
                 const Hit* hint = nullptr) const;
  // True if anything is hit with t in (t_min, t_max) (shadow rays).
  bool Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max) const;

  // The ray against one primitive only (e.g. the one a previous query reported).
  bool IntersectOne(PrimitiveKind kind, std::uint32_t index, const Eigen::Vector3f& origin,
                    const Eigen::Vector3f& dir, Hit* hit) const {
    return HitPrimitive({kind, index}, origin, dir, std::numeric_limits<float>::infinity(), hit);
  }
  // The same query testing every primitive without the tree (reference for tests).
  bool IntersectLinear(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max,
                       Hit* hit) const;

  const World& world() const { return world_; }
  std::size_t node_count() const { return nodes_.size(); }

  static constexpr float kTMin = 1e-3f;

 private:
  struct QuadF {
    Eigen::Vector3f origin, normal, dual_u, dual_v;
    float length_u, length_v;
  };
  struct Node {
    float lo[3], hi[3];
    std::uint32_t first;  // leaf: first entry in prim_refs_; inner: index of the right child
    std::uint32_t count;  // leaf: number of primitives; inner: 0 (left child = this + 1)
  };
  struct PrimRef {
    PrimitiveKind kind;
    std::uint32_t index;
  };

  bool HitPrimitive(const PrimRef& ref, const Eigen::Vector3f& origin, const Eigen::Vector3f& dir,
                    float t_max, Hit* hit) const;
  std::uint32_t Build(std::vector<std::uint32_t>& order, std::uint32_t begin, std::uint32_t end,
                      const std::vector<Eigen::AlignedBox3f>& boxes,
                      const std::vector<Eigen::Vector3f>& centroids);
  template <bool kAnyHit>
  bool Traverse(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max, Hit* hit,
                const Hit* hint) const;

  const World& world_;
  std::vector<QuadF> quads_;
  std::vector<PrimRef> unbounded_;  // huge quads (the ground) tested outside the tree
  std::vector<PrimRef> prim_refs_;
  std::vector<Node> nodes_;
};

}  // namespace planeloc::sim
