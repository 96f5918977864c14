// Surface appearance: the albedo a camera sample sees (procedural facades with windows, shop signs
// and stains; world-xy textured road and pavement; clutter) and the reflectance the LiDAR reports.
// Every feature is box-filtered by the sample footprint so nothing shimmers with distance.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "planeloc/sim/raycast.h"
#include "planeloc/sim/texture.h"
#include "planeloc/sim/world.h"

namespace planeloc::sim {

// Deterministic 32-bit mixing of integers (variation per window, per glyph, per seed stream).
std::uint32_t HashCombine(std::uint32_t a, std::uint32_t b);
std::uint32_t HashCombine(std::uint32_t a, std::uint32_t b, std::uint32_t c);

class Shader {
 public:
  // Keeps references: `world` and `bank` must outlive the shader.
  Shader(const World& world, const TextureBank& bank);

  // Albedo in [0, 1] at a hit; `point` in W; `footprint` = metres covered by the sample.
  float Albedo(const Hit& hit, const Eigen::Vector3f& point, float footprint) const;
  // LiDAR reflectance in [0, 1] for a beam arriving with unit direction `dir`.
  float Reflectance(const Hit& hit, const Eigen::Vector3f& point, const Eigen::Vector3f& dir) const;

 private:
  float Facade(const FacadeStyle& style, float u, float v, float width, float height,
               float footprint) const;
  float ShopFront(const FacadeStyle& style, float u, float v, float width, float wall,
                  float footprint) const;
  float Interior(int style, float u, float v, float width, float height, float footprint) const;
  float Windows(const FacadeStyle& style, float u, float v, float width, float height, float wall,
                float footprint) const;

  const World& world_;
  const TextureBank& bank_;
  std::vector<Eigen::Vector2f> quad_sizes_;  // |edge_u|, |edge_v| per quad
};

}  // namespace planeloc::sim
