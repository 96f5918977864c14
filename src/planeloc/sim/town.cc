#include "planeloc/sim/town.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

Vector3d Lift(const Vector2d& p, double z = 0.0) { return Vector3d(p.x(), p.y(), z); }

// An oriented rectangle in the ground plane (building or obstacle footprint).
struct Footprint {
  Vector2d centre, axis_u, axis_v;  // unit axes
  double half_u = 0, half_v = 0;
  std::vector<Vector2d> Samples(double step) const {
    std::vector<Vector2d> out;
    for (double a = -half_u; a <= half_u + 1e-9; a += std::min(step, 2 * half_u)) {
      out.push_back(centre + a * axis_u + half_v * axis_v);
      out.push_back(centre + a * axis_u - half_v * axis_v);
    }
    for (double b = -half_v; b <= half_v + 1e-9; b += std::min(step, 2 * half_v)) {
      out.push_back(centre + half_u * axis_u + b * axis_v);
      out.push_back(centre - half_u * axis_u + b * axis_v);
    }
    return out;
  }
  bool Overlaps(const Footprint& o, double shrink) const {
    // Separating axis test on the four axes.
    for (const Vector2d& axis : {axis_u, axis_v, o.axis_u, o.axis_v}) {
      const double ra = std::abs(axis.dot(axis_u)) * (half_u - shrink) +
                        std::abs(axis.dot(axis_v)) * (half_v - shrink);
      const double rb = std::abs(axis.dot(o.axis_u)) * (o.half_u - shrink) +
                        std::abs(axis.dot(o.axis_v)) * (o.half_v - shrink);
      if (std::abs(axis.dot(o.centre - centre)) > ra + rb) return false;
    }
    return true;
  }
};

struct Context {
  const StreetPath& street;
  const TownOptions& o;
  World& world;
  std::mt19937& rng;
  std::vector<Footprint> occupied;  // buildings placed so far

  double U(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  bool Chance(double p) { return U(0.0, 1.0) < p; }
  bool Clear(const std::vector<Vector2d>& points, double min_distance) const {
    for (const auto& p : points) {
      if (street.Distance(p) < min_distance) return false;
    }
    return true;
  }
  bool InsideBuilding(const Vector2d& p, double margin) const {
    for (const auto& f : occupied) {
      const Vector2d d = p - f.centre;
      if (std::abs(d.dot(f.axis_u)) < f.half_u + margin &&
          std::abs(d.dot(f.axis_v)) < f.half_v + margin)
        return true;
    }
    return false;
  }
};

struct Station {
  Vector2d p, t, n;  // position, unit tangent, unit left normal
};
Station At(const StreetPath& street, double s) {
  const Vector2d t = street.Tangent(s);
  return {street.Position(s), t, Vector2d(-t.y(), t.x())};
}

// Street chunks: pieces short enough on curves (<= 10 degrees) to approximate by rectangles.
std::vector<std::pair<double, double>> Chunks(const StreetPath& street) {
  std::vector<std::pair<double, double>> chunks;
  double start = 0.0;
  const double end = street.length();
  for (double s = 0.5; s <= end; s += 0.5) {
    const double turn =
        std::abs(std::remainder(street.Heading(s) - street.Heading(start), 2 * M_PI));
    if (turn > 10.0 * M_PI / 180.0 || s - start >= 40.0 || s + 0.5 > end) {
      chunks.emplace_back(start, s);
      start = s;
    }
  }
  return chunks;
}

void AddGround(Context& c) {
  Eigen::AlignedBox2d box;
  for (const auto& p : c.street.points()) box.extend(p);
  const Vector2d lo = box.min().array() - c.o.ground_margin,
                 size = box.sizes().array() + 2 * c.o.ground_margin;
  Quad ground;
  ground.origin = Lift(lo);
  ground.edge_u = Vector3d(size.x(), 0, 0);
  ground.edge_v = Vector3d(0, size.y(), 0);
  ground.material = Material::kAsphalt;
  c.world.AddPlanarQuad(ground, "ground");
}

void AddCentreLine(Context& c) {
  for (double s = 0.0; s + 3.0 <= c.street.length(); s += 9.0) {
    const Station m = At(c.street, s + 1.5);
    Quad dash;
    dash.origin = Lift(m.p - 1.5 * m.t - 0.06 * m.n, 0.01);
    dash.edge_u = Lift(3.0 * m.t);
    dash.edge_v = Lift(0.12 * m.n);
    dash.material = Material::kPaint;
    c.world.AddClutterQuad(dash);
  }
}

void AddSidewalksAndMarkings(Context& c) {
  const double rh = c.o.road_half_width, outer = rh + c.o.sidewalk_width + c.o.max_setback;
  for (const auto& [s0, s1] : Chunks(c.street)) {
    const Station m = At(c.street, 0.5 * (s0 + s1));
    const double half = 0.5 * (s1 - s0) + (s1 - s0 < 39.0 ? 0.15 : 0.0);  // overlap on curves
    for (const int side : {1, -1}) {
      const double lo = side > 0 ? rh : -outer, hi = side > 0 ? outer : -rh;
      std::vector<Vector2d> corners;
      for (double a : {-half, half}) {
        for (double b : {lo, hi}) corners.push_back(m.p + a * m.t + b * m.n);
      }
      if (!c.Clear(corners, rh - 0.6)) continue;
      Quad top;
      top.origin = Lift(m.p - half * m.t + lo * m.n, c.o.curb_height);
      top.edge_u = Lift(2 * half * m.t);
      top.edge_v = Lift((hi - lo) * m.n);
      top.material = Material::kSidewalk;
      c.world.AddPlanarQuad(top, "ground");
      Quad curb;  // faces the road
      const Vector2d base = m.p + side * rh * m.n;
      curb.origin = Lift(base - side * half * m.t);
      curb.edge_u = Lift(side * 2 * half * m.t);
      curb.edge_v = Vector3d(0, 0, c.o.curb_height);
      curb.material = Material::kCurb;
      c.world.AddPlanarQuad(curb, "other");
      Quad line;  // solid edge line 30 cm from the curb
      line.origin = Lift(m.p - half * m.t + side * (rh - 0.36) * m.n, 0.01);
      line.edge_u = Lift(2 * half * m.t);
      line.edge_v = Lift(0.12 * m.n);
      line.material = Material::kPaint;
      c.world.AddClutterQuad(line);
    }
  }
  AddCentreLine(c);
}

FacadeStyle RandomStyle(Context& c) {
  FacadeStyle s;
  s.wall_texture = static_cast<int>(c.rng() % 16u);
  s.wall_brightness = c.U(0.3, 0.6);
  s.floor_height = c.U(2.9, 3.6);
  s.window_width = c.U(0.9, 1.6);
  s.window_height = c.U(1.2, 1.7);
  s.window_spacing = s.window_width + c.U(0.8, 2.2);
  s.sill_height = c.U(0.8, 1.0);
  s.shop_front = c.Chance(0.5);
  s.hash = static_cast<std::uint32_t>(c.rng());
  return s;
}

struct Building {
  Footprint footprint;  // axis_u along the street, axis_v away from it
  double height = 0;
  int style = 0;
  double low_side[2] = {0, 0};  // faces at -u / +u start above this height (abutting neighbour)
  bool hide_side[2] = {false, false};
};

void EmitBuilding(Context& c, const Building& b) {
  const Footprint& f = b.footprint;
  const Vector2d fl = f.centre - f.half_u * f.axis_u - f.half_v * f.axis_v;  // front, -u end
  const Vector2d fr = f.centre + f.half_u * f.axis_u - f.half_v * f.axis_v;
  const Vector2d bl = fl + 2 * f.half_v * f.axis_v, br = fr + 2 * f.half_v * f.axis_v;
  Quad q;
  q.material = Material::kFacade;
  q.style = b.style;
  // Normals (edge_u x up) point out of the box; the vertical edge is always +z.
  auto face = [&](const Vector2d& from, const Vector2d& to, double z0) {
    q.origin = Lift(from, z0);
    q.edge_u = Lift(to - from);
    q.edge_v = Vector3d(0, 0, b.height - z0);
    if (b.height - z0 > 0.3) c.world.AddPlanarQuad(q, "facade");
  };
  const double cross = f.axis_u.x() * f.axis_v.y() - f.axis_u.y() * f.axis_v.x();
  // With axis_v pointing away from the street, the front is traversed so its normal faces it.
  if (cross > 0) {
    face(fl, fr, 0.0);
    if (!b.hide_side[1]) face(fr, br, b.low_side[1]);
    if (!b.hide_side[0]) face(bl, fl, b.low_side[0]);
  } else {
    face(fr, fl, 0.0);
    if (!b.hide_side[0]) face(fl, bl, b.low_side[0]);
    if (!b.hide_side[1]) face(br, fr, b.low_side[1]);
  }
}

void AddBuildings(Context& c) {
  const double clearance = c.o.road_half_width + c.o.sidewalk_width - 0.05;
  for (const int side : {1, -1}) {
    std::vector<Building> row;
    double s = c.U(0.0, 6.0);
    bool abut = false;
    double setback = 0.0;
    while (s < c.street.length() - 8.0) {
      const double width = c.U(8.0, 28.0), depth = c.U(9.0, 16.0);
      if (!abut) setback = c.Chance(0.4) ? 0.0 : c.U(0.5, c.o.max_setback);
      const Station m = At(c.street, s + 0.5 * width);
      Building b;
      b.footprint.axis_u = m.t;
      b.footprint.axis_v = side * m.n;
      b.footprint.half_u = 0.5 * width;
      b.footprint.half_v = 0.5 * depth;
      b.footprint.centre = m.p + side * (clearance + 0.05 + setback + 0.5 * depth) * m.n;
      bool overlap = false;
      for (const auto& other : c.occupied) overlap = overlap || b.footprint.Overlaps(other, 0.05);
      if (overlap || !c.Clear(b.footprint.Samples(2.0), clearance)) {
        s += 3.0;
        abut = false;
        continue;
      }
      const FacadeStyle style = RandomStyle(c);
      const int floors = static_cast<int>(c.U(2.0, 8.0));
      b.height = floors * style.floor_height + c.U(0.6, 1.5);
      b.style = static_cast<int>(c.world.facade_styles.size());
      c.world.facade_styles.push_back(style);
      const Footprint& f = b.footprint;
      c.world.buildings.push_back({f.centre, f.axis_u, f.axis_v, f.half_u, f.half_v, b.height});
      if (abut && !row.empty()) {  // shared wall: only the part above the lower one shows
        Building& prev = row.back();
        const int prev_far = 1;  // prev's +u face touches this building's -u face
        prev.hide_side[prev_far] = prev.height <= b.height;
        prev.low_side[prev_far] = b.height;
        b.hide_side[1 - prev_far] = b.height <= prev.height;
        b.low_side[1 - prev_far] = prev.height;
      }
      row.push_back(b);
      c.occupied.push_back(b.footprint);
      abut = c.Chance(0.45);
      s += width + (abut ? 0.0 : c.U(2.0, 12.0));
    }
    for (const auto& b : row) EmitBuilding(c, b);
  }
}

void AddTrees(Context& c) {
  const double rh = c.o.road_half_width;
  for (const int side : {1, -1}) {
    for (double s = c.U(2.0, 10.0); s < c.street.length(); s += c.U(9.0, 22.0)) {
      const Station m = At(c.street, s);
      const Vector2d p = m.p + side * (rh + 1.3) * m.n;
      if (c.street.Distance(p) < rh + 1.0 || c.InsideBuilding(p, 2.0)) continue;
      Cylinder trunk;
      trunk.base = Lift(p, c.o.curb_height);
      trunk.radius = c.U(0.12, 0.22);
      trunk.height = c.U(2.2, 3.2);
      trunk.material = Material::kBark;
      c.world.cylinders.push_back(trunk);
      const int blobs = 5 + static_cast<int>(c.rng() % 4u);
      const Vector3d top = trunk.base + Vector3d(0, 0, trunk.height);
      for (int k = 0; k < blobs; ++k) {  // a noisy crown: overlapping spheres
        Sphere crown;
        crown.center = top + Vector3d(c.U(-1.0, 1.0), c.U(-1.0, 1.0), c.U(0.6, 2.0));
        crown.radius = c.U(0.9, 1.6);
        crown.material = Material::kFoliage;
        c.world.spheres.push_back(crown);
      }
    }
  }
}

void AddPoles(Context& c) {
  const double rh = c.o.road_half_width;
  for (const int side : {1, -1}) {
    for (double s = c.U(5.0, 30.0); s < c.street.length(); s += c.U(28.0, 50.0)) {
      const Station m = At(c.street, s);
      const Vector2d p = m.p + side * (rh + 0.45) * m.n;
      if (c.street.Distance(p) < rh + 0.3 || c.InsideBuilding(p, 0.5)) continue;
      Cylinder pole;
      pole.base = Lift(p, c.o.curb_height);
      pole.radius = 0.07;
      pole.height = c.U(3.5, 7.0);
      pole.material = Material::kMetal;
      c.world.cylinders.push_back(pole);
      // Sign facing the traffic of this side (right side: traffic drives +t).
      Quad sign;
      const Vector2d face_dir = side < 0 ? Vector2d(-m.t) : Vector2d(m.t);
      const Vector2d across = side < 0 ? Vector2d(-m.n) : Vector2d(m.n);
      sign.origin = Lift(p + 0.1 * face_dir - 0.3 * across, c.o.curb_height + 2.2);
      sign.edge_u = Lift(0.6 * across);
      sign.edge_v = Vector3d(0, 0, 0.6);
      sign.material = Material::kSign;
      sign.style = static_cast<int>(c.rng() % 1000u);
      c.world.AddClutterQuad(sign);
    }
  }
}

void AddCars(Context& c) {
  const double rh = c.o.road_half_width;
  for (const int side : {1, -1}) {
    for (double s = c.U(0.0, 10.0); s < c.street.length(); s += c.U(5.6, 7.5)) {
      if (!c.Chance(0.45)) continue;
      bool straight = true;
      for (double ds = -10.0; ds <= 10.0; ds += 2.0)
        straight = straight && std::abs(c.street.Curvature(s + ds)) < 0.005;
      if (!straight) continue;
      const Station m = At(c.street, s);
      const Vector2d p = m.p + side * (rh - 1.05) * m.n;
      Footprint fp{p, m.t, m.n, 2.2, 0.9};
      if (!c.Clear(fp.Samples(1.0), rh - 2.1)) continue;
      const double heading =
          std::atan2(m.t.y(), m.t.x()) + (side > 0 ? M_PI : 0.0) + c.U(-0.04, 0.04);
      const int style = static_cast<int>(c.rng() % 100000u);
      AddParkedCar(c.world, p, heading, style);
    }
  }
}

// The rural preset's roadside, per side in stretches of 40-120 m: a cutting (55 %: grassy slopes
// rising 1-6 m in three strips whose run and steepness wander every 8 m, so the surface is locally
// flat but no plane spans more than a strip) or an open field (a farm building 10-25 m back
// now and then, trees); crash barriers along a third of the stretches. The ground quad is the road
// and the fields.
void AddCountryRoadside(Context& c) {
  const double rh = c.o.road_half_width;
  const double toe = rh + 1.5;  // the slopes start beyond the verge
  for (const int side : {1, -1}) {
    double s = 0.0;
    while (s < c.street.length()) {
      const double stretch = c.U(40.0, 120.0);
      const double end = std::min(s + stretch, c.street.length());
      const bool cutting = c.Chance(0.55);
      if (c.Chance(0.35)) {  // a crash barrier: a metal band 0.5-0.8 m high on posts
        for (double b = s; b + 4.0 <= end; b += 4.0) {
          const Station m = At(c.street, b + 2.0);
          Quad band;
          band.origin = Lift(m.p + side * (rh + 0.5) * m.n - side * 2.0 * m.t, 0.5);
          band.edge_u = Lift(side * 4.0 * m.t);
          band.edge_v = Vector3d(0, 0, 0.3);
          band.material = Material::kMetal;
          c.world.AddClutterQuad(band);
          Cylinder post;
          post.base = Lift(m.p + side * (rh + 0.6) * m.n);
          post.radius = 0.06;
          post.height = 0.8;
          post.material = Material::kMetal;
          c.world.cylinders.push_back(post);
        }
      }
      if (cutting) {
        // Each strip's run and steepness wander from profile to profile.
        double runs[3], steepness[3];
        for (int strip = 0; strip < 3; ++strip) {
          runs[strip] = c.U(1.2, 2.5);
          steepness[strip] = c.U(0.25, 0.9);
        }
        for (double a = s; a + 8.0 <= end; a += 8.0) {
          const Station m = At(c.street, a + 4.0);
          double across = toe, height = 0.0;
          for (int strip = 0; strip < 3; ++strip) {
            runs[strip] = std::clamp(runs[strip] + c.U(-0.25, 0.25), 1.2, 2.5);
            steepness[strip] = std::clamp(steepness[strip] + c.U(-0.12, 0.12), 0.25, 0.9);
            const double run = runs[strip], rise = run * steepness[strip];
            Quad slope;  // 0.3 m of overlap with the neighbours hides the steps between profiles
            slope.origin = Lift(m.p + side * across * m.n - side * 4.3 * m.t, height);
            slope.edge_u = Lift(side * 8.6 * m.t);
            slope.edge_v = Lift(side * run * m.n, rise);
            slope.material = Material::kFoliage;
            slope.style = static_cast<int>(c.rng() % 1000u);
            c.world.AddClutterQuad(slope);
            across += run;
            height += rise;
          }
          if (c.Chance(0.3)) {  // a tree on the top
            Cylinder trunk;
            trunk.base = Lift(m.p + side * (across + 1.0) * m.n, height);
            trunk.radius = c.U(0.12, 0.22);
            trunk.height = c.U(2.0, 3.0);
            trunk.material = Material::kBark;
            c.world.cylinders.push_back(trunk);
            Sphere crown;
            crown.center = trunk.base + Vector3d(0, 0, trunk.height + 1.2);
            crown.radius = c.U(1.2, 2.0);
            crown.material = Material::kFoliage;
            c.world.spheres.push_back(crown);
          }
        }
      } else {
        if (c.Chance(0.4) && end - s > 30.0) {  // a farm building far back
          const double width = c.U(10.0, 25.0), depth = c.U(8.0, 14.0);
          const Station m = At(c.street, s + 0.5 * (end - s));
          Building b;
          b.footprint.axis_u = m.t;
          b.footprint.axis_v = side * m.n;
          b.footprint.half_u = 0.5 * width;
          b.footprint.half_v = 0.5 * depth;
          b.footprint.centre = m.p + side * (rh + c.U(10.0, 25.0) + 0.5 * depth) * m.n;
          bool overlap = false;
          for (const auto& other : c.occupied)
            overlap = overlap || b.footprint.Overlaps(other, 0.05);
          if (!overlap && c.Clear(b.footprint.Samples(2.0), rh + 8.0)) {
            const FacadeStyle style = RandomStyle(c);
            b.height = static_cast<int>(c.U(1.0, 3.0)) * style.floor_height + c.U(0.6, 1.5);
            b.style = static_cast<int>(c.world.facade_styles.size());
            c.world.facade_styles.push_back(style);
            const Footprint& f = b.footprint;
            c.world.buildings.push_back(
                {f.centre, f.axis_u, f.axis_v, f.half_u, f.half_v, b.height});
            c.occupied.push_back(b.footprint);
            EmitBuilding(c, b);
          }
        }
        for (double t = s + c.U(2.0, 10.0); t < end; t += c.U(8.0, 25.0)) {  // field trees
          const Station m = At(c.street, t);
          const Vector2d p = m.p + side * (rh + c.U(3.0, 15.0)) * m.n;
          if (c.street.Distance(p) < rh + 2.5 || c.InsideBuilding(p, 2.0)) continue;
          Cylinder trunk;
          trunk.base = Lift(p);
          trunk.radius = c.U(0.15, 0.3);
          trunk.height = c.U(2.0, 3.5);
          trunk.material = Material::kBark;
          c.world.cylinders.push_back(trunk);
          const int blobs = 4 + static_cast<int>(c.rng() % 4u);
          for (int k = 0; k < blobs; ++k) {
            Sphere crown;
            crown.center =
                trunk.base + Vector3d(c.U(-1.2, 1.2), c.U(-1.2, 1.2), trunk.height + c.U(0.6, 2.2));
            crown.radius = c.U(1.0, 1.8);
            crown.material = Material::kFoliage;
            c.world.spheres.push_back(crown);
          }
        }
      }
      s = end;
    }
  }
}

void AddRoadMarkings(Context& c, double edge_offset) {
  for (const auto& [s0, s1] : Chunks(c.street)) {
    const Station m = At(c.street, 0.5 * (s0 + s1));
    const double half = 0.5 * (s1 - s0);
    for (const int side : {1, -1}) {
      Quad line;  // solid edge line
      line.origin = Lift(m.p - half * m.t + side * edge_offset * m.n, 0.01);
      line.edge_u = Lift(2 * half * m.t);
      line.edge_v = Lift(0.12 * m.n);
      line.material = Material::kPaint;
      c.world.AddClutterQuad(line);
    }
  }
}

}  // namespace

void TownOptions::Check() const {
  if (!(road_half_width > 2.0)) throw OptionsError("TownOptions.road_half_width must be > 2 m");
  if (!(sidewalk_width > 0.5)) throw OptionsError("TownOptions.sidewalk_width must be > 0.5 m");
  if (!(max_setback >= 0.5)) throw OptionsError("TownOptions.max_setback must be >= 0.5 m");
  if (!(curb_height >= 0.0 && curb_height < 0.5)) throw OptionsError("TownOptions.curb_height");
  if (!(ground_margin >= 0.0)) throw OptionsError("TownOptions.ground_margin must be >= 0");
}

void AddParkedCar(World& world, const Vector2d& position, double heading, int style) {
  world.AddClutterBox(Lift(position, 0.22), heading, 4.3, 1.75, 0.82, Material::kCarPaint, style);
  const Vector2d back(std::cos(heading), std::sin(heading));
  world.AddClutterBox(Lift(position - 0.25 * back, 1.04), heading, 2.3, 1.55, 0.52,
                      Material::kCarGlass, style);
}

World BuildTown(const StreetPath& street, std::uint32_t seed, const TownOptions& options) {
  options.Check();
  World world;
  std::mt19937 rng(seed);
  Context c{street, options, world, rng, {}};
  AddGround(c);
  if (options.rural) {
    AddCentreLine(c);
    AddRoadMarkings(c, options.road_half_width - 0.36);
    AddCountryRoadside(c);
    return world;
  }
  AddSidewalksAndMarkings(c);
  AddBuildings(c);
  if (options.clutter) {
    AddTrees(c);
    AddPoles(c);
    AddCars(c);
  }
  return world;
}

}  // namespace planeloc::sim
