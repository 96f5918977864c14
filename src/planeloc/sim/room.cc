#include "planeloc/sim/room.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "planeloc/sim/shading.h"
#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

// Faces smaller than this are clutter, not GT planes: a plane map's extraction keeps planes of
// about this size and up (the acceptance counts planes of >= 1 m^2).
constexpr double kMinGtArea = 0.5;

// A wall-standing box: `centre` is the middle of its bottom face, `along` the wall's direction,
// `out` the unit normal of its front (towards the room). Front, top and the two sides are
// surfaces; the back against the wall is never seen. Faces of kMinGtArea and more are GT planes.
void AddFurnitureBox(World& world, const Eigen::Vector3d& centre, const Eigen::Vector3d& along,
                     const Eigen::Vector3d& out, double length, double depth, double height,
                     int style) {
  Quad q;
  q.material = Material::kInterior;
  q.style = style;
  const auto add = [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& eu,
                       const Eigen::Vector3d& ev, const char* kind) {
    q.origin = origin;
    q.edge_u = eu;
    q.edge_v = ev;
    if (eu.cross(ev).norm() >= kMinGtArea) {
      world.AddPlanarQuad(q, kind);
    } else {
      world.AddClutterQuad(q);
    }
  };
  const Eigen::Vector3d half_l = 0.5 * length * along, half_d = 0.5 * depth * out;
  const Eigen::Vector3d h = height * kUp;
  // Each face's edge_u x edge_v points away from the box (along x up = out, out x along = up).
  add(centre - half_l + half_d, length * along, h, "facade");               // front
  add(centre - half_l - half_d + h, depth * out, length * along, "other");  // top
  add(centre - half_l - half_d, depth * out, h, "facade");                  // side at -along
  add(centre + half_l + half_d, -depth * out, h, "facade");                 // side at +along
}

// A table: a top (GT plane when large enough), a thin apron as clutter, four legs, and a few
// objects on it.
void AddTable(World& world, const Eigen::Vector3d& centre, const Eigen::Vector3d& along,
              const Eigen::Vector3d& out, double length, double depth, double height, int style,
              std::mt19937& rng) {
  const Eigen::Vector3d half_l = 0.5 * length * along, half_d = 0.5 * depth * out;
  Quad top;
  top.material = Material::kInterior;
  top.style = style;
  top.origin = centre - half_l - half_d + height * kUp;
  top.edge_u = depth * out;
  top.edge_v = length * along;
  if (length * depth >= kMinGtArea) {
    world.AddPlanarQuad(top, "other");
  } else {
    world.AddClutterQuad(top);
  }
  Quad apron = top;
  apron.material = Material::kCurb;
  apron.origin = centre - half_l + half_d + (height - 0.05) * kUp;
  apron.edge_u = length * along;
  apron.edge_v = 0.05 * kUp;
  world.AddClutterQuad(apron);
  for (const double sl : {-1.0, 1.0}) {
    for (const double sd : {-1.0, 1.0}) {
      Cylinder leg;
      leg.base = centre + sl * (half_l - 0.06 * along) + sd * (half_d - 0.06 * out);
      leg.radius = 0.025;
      leg.height = height;
      leg.material = Material::kMetal;
      world.cylinders.push_back(leg);
    }
  }
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int items = 1 + static_cast<int>(rng() % 3);
  for (int i = 0; i < items; ++i) {
    const Eigen::Vector3d at = centre + (unit(rng) - 0.5) * (length - 0.4) * along +
                               (unit(rng) - 0.5) * (depth - 0.3) * out + height * kUp;
    world.AddClutterBox(at, std::atan2(along.y(), along.x()) + 0.5 * (unit(rng) - 0.5),
                        0.15 + 0.25 * unit(rng), 0.1 + 0.2 * unit(rng), 0.05 + 0.3 * unit(rng),
                        Material::kCarPaint, static_cast<int>(rng() % 1000));
  }
}

// Clutter on the floor next to a wall: stacked boxes, a ball or a bin.
void AddFloorClutter(World& world, const Eigen::Vector3d& at, const Eigen::Vector3d& along,
                     std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double heading = std::atan2(along.y(), along.x());
  switch (rng() % 3) {
    case 0: {
      double z = 0.0;
      const int stack = 1 + static_cast<int>(rng() % 3);
      for (int i = 0; i < stack; ++i) {
        const double size = 0.55 - 0.12 * i;
        const double h = 0.25 + 0.25 * unit(rng);
        world.AddClutterBox(at + z * kUp, heading + 0.4 * (unit(rng) - 0.5), size, size, h,
                            Material::kCarPaint, static_cast<int>(rng() % 1000));
        z += h;
      }
      break;
    }
    case 1: {
      Sphere ball;
      ball.radius = 0.12 + 0.2 * unit(rng);
      ball.center = at + ball.radius * kUp;
      ball.material = Material::kFoliage;
      world.spheres.push_back(ball);
      break;
    }
    default: {
      Cylinder bin;
      bin.base = at;
      bin.radius = 0.15 + 0.1 * unit(rng);
      bin.height = 0.4 + 0.4 * unit(rng);
      bin.material = Material::kMetal;
      world.cylinders.push_back(bin);
      break;
    }
  }
}

}  // namespace

void RoomOptions::Check() const {
  if (!(length >= 5.0 && width >= 5.0 && height >= 2.5 && length <= 50.0 && width <= 50.0 &&
        height <= 20.0)) {
    throw OptionsError("RoomOptions: length and width in [5, 50] m, height in [2.5, 20] m");
  }
}

void FlightOptions::Check() const {
  if (!(mean_speed > 0.0 && mean_speed <= 5.0)) {
    throw OptionsError("FlightOptions.mean_speed must be in (0, 5] m/s");
  }
  if (!(peak_yaw_rate_deg >= 0.0 && peak_yaw_rate_deg <= 500.0)) {
    throw OptionsError("FlightOptions.peak_yaw_rate_deg must be in [0, 500]");
  }
  if (!(tilt_deg >= 0.0 && tilt_deg <= 45.0)) {
    throw OptionsError("FlightOptions.tilt_deg must be in [0, 45]");
  }
}

World BuildRoom(std::uint32_t seed, const RoomOptions& options) {
  options.Check();
  World world;
  const double hl = 0.5 * options.length, hw = 0.5 * options.width, height = options.height;
  Quad floor;
  floor.material = Material::kSidewalk;  // floor tiles, textured in world xy
  floor.origin = Eigen::Vector3d(-hl, -hw, 0.0);
  floor.edge_u = Eigen::Vector3d(options.length, 0, 0);
  floor.edge_v = Eigen::Vector3d(0, options.width, 0);
  world.AddPlanarQuad(floor, "ground");
  Quad ceiling;
  ceiling.material = Material::kCurb;  // concrete
  ceiling.origin = Eigen::Vector3d(-hl, -hw, height);
  ceiling.edge_u = Eigen::Vector3d(0, options.width, 0);
  ceiling.edge_v = Eigen::Vector3d(options.length, 0, 0);
  world.AddPlanarQuad(ceiling, "other");

  std::mt19937 rng(HashCombine(seed, 0x700du));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Walls by their inward normal; `along` = up x inward, so that along x up = inward.
  const Eigen::Vector3d inward[4] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                     -Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY()};
  int style = static_cast<int>(HashCombine(seed, 0x57u) % 10000u) * 16;
  for (int w = 0; w < 4; ++w) {
    const Eigen::Vector3d& n = inward[w];
    const Eigen::Vector3d along = kUp.cross(n);
    const double half_span = std::abs(n.x()) > 0.5 ? hw : hl;  // the wall's half length
    const double to_wall = std::abs(n.x()) > 0.5 ? hl : hw;
    const Eigen::Vector3d foot = -to_wall * n;  // the wall's middle at floor level
    Quad wall;
    wall.material = Material::kInterior;
    wall.style = style++;
    wall.origin = foot - half_span * along;
    wall.edge_u = 2.0 * half_span * along;
    wall.edge_v = height * kUp;
    world.AddPlanarQuad(wall, "facade");

    // Furniture along the wall, left to right, with gaps; nothing deeper than 1.1 m into the room.
    double s = -half_span + 0.3 + 0.8 * unit(rng);
    while (true) {
      const int kind = static_cast<int>(rng() % 4);
      const double length = kind == 2 ? 1.4 + 0.4 * unit(rng) : 0.9 + 1.1 * unit(rng);
      if (s + length > half_span - 0.3) break;
      const Eigen::Vector3d mid = foot + (s + 0.5 * length) * along;
      if (kind == 0) {  // cabinet or shelf
        const double depth = 0.45 + 0.15 * unit(rng);
        AddFurnitureBox(world, mid + (0.02 + 0.5 * depth) * n, along, n, length, depth,
                        1.8 + 0.4 * unit(rng), style++);
      } else if (kind == 1) {  // sideboard
        const double depth = 0.5 + 0.1 * unit(rng);
        AddFurnitureBox(world, mid + (0.02 + 0.5 * depth) * n, along, n, length, depth,
                        0.8 + 0.2 * unit(rng), style++);
      } else if (kind == 2) {  // table
        const double depth = 0.7 + 0.15 * unit(rng);
        AddTable(world, mid + (0.1 + 0.5 * depth) * n, along, n, length, depth, 0.74, style++, rng);
      } else if (options.clutter) {
        AddFloorClutter(world, mid + (0.3 + 0.5 * unit(rng)) * n, along, rng);
      }
      s += length + 0.2 + 1.0 * unit(rng);
    }
  }
  if (options.clutter) {  // the corners
    for (const double sx : {-1.0, 1.0}) {
      for (const double sy : {-1.0, 1.0}) {
        if (unit(rng) < 0.5) continue;
        AddFloorClutter(world, Eigen::Vector3d(sx * (hl - 0.5), sy * (hw - 0.5), 0.0),
                        Eigen::Vector3d::UnitX(), rng);
      }
    }
  }
  return world;
}

Eigen::AlignedBox3d RoomFlightSpace(const RoomOptions& options) {
  options.Check();
  const double hl = 0.5 * options.length - 1.5, hw = 0.5 * options.width - 1.5;
  return Eigen::AlignedBox3d(Eigen::Vector3d(-hl, -hw, 0.7),
                             Eigen::Vector3d(hl, hw, options.height - 1.2));
}

std::vector<Eigen::Vector3d> RoomSurveyStations(const RoomOptions& options) {
  const Eigen::AlignedBox3d space = RoomFlightSpace(options);
  const Eigen::Vector3d half = 0.5 * space.sizes();
  return {Eigen::Vector3d(-0.6 * half.x(), -0.4 * half.y(), 1.5),
          Eigen::Vector3d(0.65 * half.x(), -0.3 * half.y(), 1.5),
          Eigen::Vector3d(0.0, 0.7 * half.y(), 1.5)};
}

RoomFlight::RoomFlight(const RoomOptions& room, const FlightOptions& flight, std::uint32_t seed) {
  flight.Check();
  const Eigen::AlignedBox3d space = RoomFlightSpace(room);
  centre_ = space.center();
  amplitude_ = 0.5 * space.sizes();
  std::mt19937 rng(HashCombine(seed, 0xf1197u));
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  // Two sinusoids per axis, 0.65 and 0.35 of the half extent, so the flight never leaves the
  // space; incommensurate frequency ratios so the path does not repeat within a sequence.
  const double ratio[3][2] = {{1.0, 2.31}, {1.27, 2.93}, {0.83, 1.91}};
  const double share[2] = {0.65, 0.35};
  double speed_sq = 0.0;  // mean squared speed for a base frequency of 1 rad/s
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 2; ++k) {
      const double a = share[k] * amplitude_[axis];
      speed_sq += 0.5 * a * a * ratio[axis][k] * ratio[axis][k];
    }
  }
  // The mean of |v| of such a path is about 0.9 of its root mean square.
  const double base = flight.mean_speed / (0.9 * std::sqrt(speed_sq));
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 2; ++k) {
      omega_[axis][k] = base * ratio[axis][k];
      phase_[axis][k] = phase(rng);
    }
  }
  const double peak = flight.peak_yaw_rate_deg * M_PI / 180.0;
  yaw0_ = phase(rng);
  yaw_drift_ = (rng() % 2 ? 0.15 : -0.15) * peak;
  yaw_omega_[0] = 0.3;
  yaw_omega_[1] = 1.1;
  yaw_amp_[0] = 0.45 * peak / yaw_omega_[0];
  yaw_amp_[1] = 0.4 * peak / yaw_omega_[1];
  yaw_phase_[0] = phase(rng);
  yaw_phase_[1] = phase(rng);
  tilt_ = flight.tilt_deg * M_PI / 180.0;
  tilt_phase_[0] = phase(rng);
  tilt_phase_[1] = phase(rng);
}

Rigid3d RoomFlight::WorldFromCamAt(double t) const {
  Eigen::Vector3d position = centre_;
  const double share[2] = {0.65, 0.35};
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 2; ++k) {
      position[axis] +=
          share[k] * amplitude_[axis] * std::sin(omega_[axis][k] * t + phase_[axis][k]);
    }
  }
  const double yaw = yaw0_ + yaw_drift_ * t +
                     yaw_amp_[0] * std::sin(yaw_omega_[0] * t + yaw_phase_[0]) +
                     yaw_amp_[1] * std::sin(yaw_omega_[1] * t + yaw_phase_[1]);
  // Slightly down on average: the floor is the plane every view should hold.
  const double pitch = -0.12 + 0.6 * tilt_ * std::sin(0.7 * t + tilt_phase_[0]);
  const double roll = 0.5 * tilt_ * std::sin(0.9 * t + tilt_phase_[1]);
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                std::sin(pitch));
  const Eigen::Vector3d right = forward.cross(kUp).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d rotation;
  rotation << right, down, forward;
  rotation = Eigen::AngleAxisd(roll, forward).toRotationMatrix() * rotation;
  return Rigid3d(rotation, position);
}

}  // namespace planeloc::sim
