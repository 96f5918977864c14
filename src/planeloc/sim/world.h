// The simulator's world model: a list of textured surface primitives (planar quads, spheres,
// vertical cylinders) in a z-up world frame W (metres, ground at z = 0), and the ground-truth
// planes those quads lie on. Everything is plain data so tests can build a world by hand.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "planeloc/geometry/plane.h"

namespace planeloc::sim {

// Surface kinds; each has its own texture and LiDAR reflectance (see shading.h).
enum class Material : std::uint8_t {
  kAsphalt,   // road, world-xy textured
  kSidewalk,  // paving slabs, world-xy textured
  kCurb,      // concrete
  kPaint,     // lane markings
  kFacade,    // wall + windows + shop signs, style from World::facade_styles
  kFoliage,   // tree crowns
  kBark,      // tree trunks
  kCarPaint,
  kCarGlass,
  kMetal,     // poles
  kSign,      // traffic signs on poles
  kMarker,    // test target: black square on white, see render_test.cc
  kInterior,  // indoor wall or furniture: wall texture with posters and marker boards (room.h)
};

// A planar parallelogram origin + a * edge_u + b * edge_v, a, b in [0, 1]. Texture coordinates
// are metres along edge_u / edge_v plus uv_offset. For facades edge_v points up (v = height).
struct Quad {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitY();
  Material material = Material::kFacade;
  int style = 0;      // index into World::facade_styles for facades; variation seed otherwise
  int plane_id = -1;  // index into World::planes, -1 for clutter surfaces
  Eigen::Vector2d uv_offset = Eigen::Vector2d::Zero();

  // Unit normal edge_u x edge_v (the side a facade shows to the street).
  Eigen::Vector3d Normal() const { return edge_u.cross(edge_v).normalized(); }
  std::vector<Eigen::Vector3d> Corners() const {
    return {origin, origin + edge_u, origin + edge_u + edge_v, origin + edge_v};
  }
};

struct Sphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 1.0;
  Material material = Material::kFoliage;
  int style = 0;
};

// Vertical (world z) open cylinder from base.z to base.z + height.
struct Cylinder {
  Eigen::Vector3d base = Eigen::Vector3d::Zero();
  double radius = 0.1;
  double height = 1.0;
  Material material = Material::kMetal;
  int style = 0;
};

// Per-building facade parameters (metres).
struct FacadeStyle {
  int wall_texture = 0;  // index into the wall texture bank
  double wall_brightness = 0.6;
  double floor_height = 3.0;  // storey height
  double window_width = 1.2;
  double window_height = 1.5;
  double window_spacing = 3.0;  // horizontal period
  double sill_height = 0.9;     // window bottom above the storey floor
  bool shop_front = false;      // ground floor with shop windows and a sign band
  std::uint32_t hash = 0;       // per-building variation seed
};

struct GtPlane {
  int id = 0;
  std::string kind;                      // "ground" | "facade" | "other"
  Plane plane;                           // in W
  std::vector<Eigen::Vector3d> polygon;  // visible extent, in W, on the plane
};

// A building's ground rectangle in W's xy plane (metres): centre, unit axes and half extents.
struct BuildingOutline {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d axis_u = Eigen::Vector2d::UnitX();  // along the street
  Eigen::Vector2d axis_v = Eigen::Vector2d::UnitY();  // away from the street
  double half_u = 0.0, half_v = 0.0;
  double height = 0.0;
  // True if `point` lies inside the rectangle grown by `margin` metres on every side.
  bool Contains(const Eigen::Vector2d& point, double margin) const {
    const Eigen::Vector2d d = point - centre;
    return std::abs(d.dot(axis_u)) < half_u + margin && std::abs(d.dot(axis_v)) < half_v + margin;
  }
};

struct World {
  std::vector<Quad> quads;
  std::vector<Sphere> spheres;
  std::vector<Cylinder> cylinders;
  std::vector<FacadeStyle> facade_styles;
  std::vector<GtPlane> planes;
  // Building i's outline (its facades use facade_styles[i]); filled by BuildTown, may be empty in
  // hand-made worlds. Used to find free ground for new walls (world_changes.h).
  std::vector<BuildingOutline> buildings;

  // Adds a quad that is its own GT plane of `kind` (id = index in planes); returns the quad index.
  int AddPlanarQuad(const Quad& quad, const std::string& kind);
  // Adds a clutter quad (no GT plane).
  void AddClutterQuad(const Quad& quad) { quads.push_back(quad); }
  // Five visible faces (four sides and the top) of an axis-aligned-in-heading box as clutter.
  // `center_bottom` is the centre of the bottom face, `heading` rotates about z (radians).
  void AddClutterBox(const Eigen::Vector3d& center_bottom, double heading, double length,
                     double width, double height, Material material, int style);

  // Unsigned distance (metres) from `point` to the nearest surface (brute force, for tests).
  double DistanceToSurface(const Eigen::Vector3d& point) const;
};

// Distance from `point` to the parallelogram (not just its plane).
double DistanceToQuad(const Quad& quad, const Eigen::Vector3d& point);

}  // namespace planeloc::sim
