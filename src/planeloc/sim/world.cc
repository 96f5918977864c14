#include "planeloc/sim/world.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace planeloc::sim {

int World::AddPlanarQuad(const Quad& quad, const std::string& kind) {
  GtPlane gt;
  gt.id = static_cast<int>(planes.size());
  gt.kind = kind;
  gt.plane = Plane::FromPointAndNormal(quad.origin, quad.Normal());
  gt.polygon = quad.Corners();
  planes.push_back(gt);
  Quad stored = quad;
  stored.plane_id = gt.id;
  quads.push_back(stored);
  return static_cast<int>(quads.size()) - 1;
}

void World::AddClutterBox(const Eigen::Vector3d& center_bottom, double heading, double length,
                          double width, double height, Material material, int style) {
  const Eigen::Vector3d forward(std::cos(heading), std::sin(heading), 0.0);
  const Eigen::Vector3d left(-forward.y(), forward.x(), 0.0);
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d f = forward * length, l = left * width, h = up * height;
  const Eigen::Vector3d rear_right = center_bottom - 0.5 * f - 0.5 * l;
  Quad q;
  q.material = material;
  q.style = style;
  // Each face's normal (edge_u x edge_v) points outwards.
  auto add = [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& eu,
                 const Eigen::Vector3d& ev) {
    q.origin = origin;
    q.edge_u = eu;
    q.edge_v = ev;
    AddClutterQuad(q);
  };
  add(rear_right, f, h);           // right side (normal -left)
  add(rear_right + f + l, -f, h);  // left side
  add(rear_right + l, -l, h);      // rear
  add(rear_right + f, l, h);       // front
  add(rear_right + h, f, l);       // top
}

double DistanceToQuad(const Quad& quad, const Eigen::Vector3d& point) {
  const Eigen::Vector3d rel = point - quad.origin;
  const double uu = quad.edge_u.squaredNorm(), vv = quad.edge_v.squaredNorm();
  const double uv = quad.edge_u.dot(quad.edge_v);
  const double det = uu * vv - uv * uv;
  const double ru = rel.dot(quad.edge_u), rv = rel.dot(quad.edge_v);
  const double a = std::clamp((vv * ru - uv * rv) / det, 0.0, 1.0);
  const double b = std::clamp((uu * rv - uv * ru) / det, 0.0, 1.0);
  return (quad.origin + a * quad.edge_u + b * quad.edge_v - point).norm();
}

double World::DistanceToSurface(const Eigen::Vector3d& point) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& quad : quads) best = std::min(best, DistanceToQuad(quad, point));
  for (const auto& s : spheres)
    best = std::min(best, std::abs((point - s.center).norm() - s.radius));
  for (const auto& c : cylinders) {
    const double radial = std::abs((point - c.base).head<2>().norm() - c.radius);
    const double below = std::max(0.0, c.base.z() - point.z());
    const double above = std::max(0.0, point.z() - c.base.z() - c.height);
    best = std::min(best, std::hypot(radial, below + above));
  }
  return best;
}

}  // namespace planeloc::sim
