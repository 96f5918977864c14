#include "planeloc/sim/world_changes.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include "planeloc/sim/shading.h"
#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr const char* kExpectedForm =
    "a preset (renovation, none) or comma-separated KEY=VALUE items: moved=FRACTION (0..1), "
    "offset=MIN:MAX (metres, 0 < MIN <= MAX <= 2), removed=N, new=N, cars=N (N in 0..100)";
constexpr const char* kExample =
    "e.g. --changes renovation or --changes moved=0.3,offset=0.1:0.5,removed=1,new=1,cars=6";
constexpr int kMaxCount = 100;
constexpr double kMaxOffset = 2.0;       // metres; more is a new building, not a renovation
constexpr double kBuildingReach = 20.0;  // metres from a camera centre to a changed facade
constexpr double kSiteReach = 15.0;      // metres from a camera centre to a new wall or car
// Independent streams per kind of change (HashCombine(seed, kChangesStream, kind)).
constexpr std::uint32_t kChangesStream = 4u;
enum Stream : std::uint32_t { kRemovedStream = 1, kMovedStream, kNewWallStream, kCarStream };

[[noreturn]] void FailSpec(const std::string& spec, const std::string& reason) {
  throw InputError("", 0, fmt::format("--changes {}: {}; expected {}", spec, reason, kExpectedForm),
                   kExample);
}

bool ParseDouble(const std::string& text, double* value) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, *value);
  return error == std::errc() && stop == end && std::isfinite(*value);
}

bool ParseCount(const std::string& text, int* value) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, *value);
  return error == std::errc() && stop == end && *value >= 0 && *value <= kMaxCount;
}

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  if (!text.empty() && text.back() == separator) parts.emplace_back();
  return parts;
}

WorldChangesOptions Renovation() {
  WorldChangesOptions options;
  options.moved_fraction = 0.3;
  options.removed_buildings = 1;
  options.new_walls = 1;
  options.parked_cars = 6;
  return options;
}

// k of the indices 0..n-1 drawn without replacement (partial Fisher-Yates with `rng() %`, which,
// unlike std::shuffle, is the same on every standard library), returned in increasing order.
std::vector<int> PickIndices(int n, int k, std::mt19937& rng) {
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = i;
  k = std::min(k, n);
  for (int i = 0; i < k; ++i) {
    const int j = i + static_cast<int>(rng() % static_cast<std::uint32_t>(n - i));
    std::swap(order[static_cast<std::size_t>(i)], order[static_cast<std::size_t>(j)]);
  }
  order.resize(static_cast<std::size_t>(k));
  std::sort(order.begin(), order.end());
  return order;
}

double Uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

double HorizontalDistanceToDrive(const Vector2d& point, const std::vector<Vector3d>& centres) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& c : centres) best = std::min(best, (c.head<2>() - point).norm());
  return best;
}

bool QuadNearDrive(const Quad& quad, const std::vector<Vector3d>& centres) {
  for (const auto& c : centres) {
    if (DistanceToQuad(quad, Vector3d(c.x(), c.y(), quad.origin.z())) < kBuildingReach) return true;
  }
  return false;
}

// Facade quads per building (facade quads use `style` as the building index), in quad order.
std::map<int, std::vector<int>> FacadesByBuilding(const World& world) {
  std::map<int, std::vector<int>> buildings;
  for (std::size_t i = 0; i < world.quads.size(); ++i) {
    const Quad& q = world.quads[i];
    if (q.material == Material::kFacade && q.plane_id >= 0) {
      buildings[q.style].push_back(static_cast<int>(i));
    }
  }
  return buildings;
}

// A free-standing building has its front and both side walls from the ground up: it shares no
// wall with a neighbour (a shared wall starts above the lower roof or is not emitted at all), so
// removing it leaves no neighbour's box open.
bool FreeStanding(const World& world, const std::vector<int>& facades) {
  if (facades.size() != 3) return false;
  for (const int i : facades) {
    if (std::abs(world.quads[static_cast<std::size_t>(i)].origin.z()) > 1e-9) return false;
  }
  return true;
}

bool SameColumn(const Vector3d& a, const Vector3d& b) { return (a - b).head<2>().norm() < 1e-6; }

// Shifts the ground-level facade `moved` by `offset` metres along its normal and keeps its
// building closed: the vertical edges of the building's walls that met its corners are dragged
// along (their planes stay), and where a corner had no wall down to the ground (a wall shared
// with a neighbour, hidden or starting above the neighbour's roof) a narrow clutter quad closes
// the step between the old and the new corner up to that wall. Updates the GT planes of `world`
// (the moved plane, and the polygons of the stretched walls).
void MoveFacade(World& world, int moved, const std::vector<int>& building, double offset) {
  const Quad before = world.quads[static_cast<std::size_t>(moved)];
  const Vector3d shift = offset * before.Normal();
  const double top = before.origin.z() + before.edge_v.z();
  for (const Vector3d& corner : {before.origin, Vector3d(before.origin + before.edge_u)}) {
    double lowest_wall = top;  // the lowest start of a wall that meets this corner
    for (const int other : building) {
      if (other == moved) continue;
      Quad& wall = world.quads[static_cast<std::size_t>(other)];
      const Vector3d direction = wall.edge_u.normalized();
      if (SameColumn(wall.origin, corner)) {
        wall.origin += shift;
        wall.edge_u -= shift;
        wall.uv_offset.x() += shift.dot(direction);  // the texture stays where it was
      } else if (SameColumn(wall.origin + wall.edge_u, corner)) {
        wall.edge_u += shift;
      } else {
        continue;
      }
      lowest_wall = std::min(lowest_wall, wall.origin.z());
      world.planes[static_cast<std::size_t>(wall.plane_id)].polygon = wall.Corners();
    }
    if (lowest_wall > before.origin.z() + 0.3) {
      Quad step = before;
      step.origin = corner;
      step.edge_u = shift;
      step.edge_v = Vector3d(0.0, 0.0, lowest_wall - before.origin.z());
      step.plane_id = -1;
      world.AddClutterQuad(step);
    }
  }
  Quad& quad = world.quads[static_cast<std::size_t>(moved)];
  quad.origin += shift;
  GtPlane& plane = world.planes[static_cast<std::size_t>(quad.plane_id)];
  plane.plane = Plane::FromPointAndNormal(quad.origin, quad.Normal());
  plane.polygon = quad.Corners();
}

FacadeStyle DrawStyle(std::mt19937& rng) {
  FacadeStyle s;
  s.wall_texture = static_cast<int>(rng() % 16u);
  s.wall_brightness = Uniform(rng, 0.3, 0.6);
  s.floor_height = Uniform(rng, 2.9, 3.6);
  s.window_width = Uniform(rng, 0.9, 1.6);
  s.window_height = Uniform(rng, 1.2, 1.7);
  s.window_spacing = s.window_width + Uniform(rng, 0.8, 2.2);
  s.sill_height = Uniform(rng, 0.8, 1.0);
  s.shop_front = (rng() & 1u) != 0;
  s.hash = static_cast<std::uint32_t>(rng());
  return s;
}

struct Station {
  double s = 0.0;
  int side = 1;  // +1 left of the centre line, -1 right
};

Vector2d LeftNormal(const Vector2d& tangent) { return Vector2d(-tangent.y(), tangent.x()); }

bool InsideAnyBuilding(const World& world, const Vector2d& point, double margin) {
  for (const auto& b : world.buildings) {
    if (b.Contains(point, margin)) return true;
  }
  return false;
}

// One new wall facing the street beside a station near the drive, on free ground between the
// buildings (the town's street clearance and 1 m from any building); false when no site is found.
bool AddNewWall(World& world, const StreetPath& street, const std::vector<Station>& stations,
                const TownOptions& town, std::mt19937& rng) {
  const double clearance = town.road_half_width + town.sidewalk_width - 0.05;
  for (int attempt = 0; attempt < 200 && !stations.empty(); ++attempt) {
    const Station& station = stations[rng() % stations.size()];
    const double width = Uniform(rng, 6.0, 12.0), height = Uniform(rng, 4.0, 10.0);
    const double setback = Uniform(rng, 0.0, 2.0);
    const Vector2d t = street.Tangent(station.s), n = LeftNormal(t);
    const Vector2d middle =
        street.Position(station.s) + station.side * (clearance + 0.05 + setback) * n;
    BuildingOutline outline;
    outline.axis_u = t;
    outline.axis_v = station.side * n;
    outline.half_u = 0.5 * width;
    outline.half_v = 0.25;
    outline.centre = middle + 0.25 * outline.axis_v;  // the wall is the outline's street side
    outline.height = height;
    bool free = true;
    for (double a = -outline.half_u; a <= outline.half_u + 1e-9 && free; a += 0.5) {
      for (const double b : {-outline.half_v, outline.half_v}) {
        const Vector2d p = outline.centre + a * outline.axis_u + b * outline.axis_v;
        free = free && street.Distance(p) >= clearance && !InsideAnyBuilding(world, p, 1.0);
      }
    }
    if (!free) continue;
    Quad wall;
    wall.origin =
        Vector3d(middle.x(), middle.y(), 0.0) -
        Vector3d(station.side * outline.half_u * t.x(), station.side * outline.half_u * t.y(), 0.0);
    // edge_u x up faces the street: +t on the left side (normal -n), -t on the right.
    wall.edge_u = Vector3d(station.side * width * t.x(), station.side * width * t.y(), 0.0);
    wall.edge_v = Vector3d(0.0, 0.0, height);
    wall.material = Material::kFacade;
    wall.style = static_cast<int>(world.facade_styles.size());
    world.facade_styles.push_back(DrawStyle(rng));
    world.buildings.push_back(outline);
    world.AddPlanarQuad(wall, "facade");
    return true;
  }
  return false;
}

// Centres of the parked cars' body boxes (their roof quads' centres), in W's xy.
std::vector<Vector2d> ParkedCarCentres(const World& world) {
  std::vector<Vector2d> centres;
  for (const Quad& q : world.quads) {
    if (q.material == Material::kCarPaint && std::abs(q.Normal().z()) > 0.9) {
      centres.push_back((q.origin + 0.5 * q.edge_u + 0.5 * q.edge_v).head<2>());
    }
  }
  return centres;
}

// Adds up to `count` parked cars at free curbside spots on straight stretches near the drive,
// spots as the town's own cars (town.cc) use them; returns how many were placed.
int AddParkedCars(World& world, const StreetPath& street,
                  const std::vector<Vector3d>& camera_centres, const TownOptions& town, int count,
                  std::mt19937& rng) {
  const double rh = town.road_half_width;
  std::vector<std::pair<Vector2d, double>> spots;  // position, heading
  for (double s = 10.0; s + 10.0 < street.length(); s += 1.0) {
    bool straight = true;
    for (double ds = -10.0; ds <= 10.0; ds += 2.0)
      straight = straight && std::abs(street.Curvature(s + ds)) < 0.005;
    if (!straight) continue;
    const Vector2d t = street.Tangent(s), n = LeftNormal(t);
    for (const int side : {1, -1}) {
      const Vector2d p = street.Position(s) + side * (rh - 1.05) * n;
      if (HorizontalDistanceToDrive(p, camera_centres) > kSiteReach) continue;
      bool clear = true;  // the whole footprint stays on this street's curbside lane
      for (const double a : {-2.2, 2.2}) {
        for (const double b : {-0.9, 0.9})
          clear = clear && street.Distance(p + a * t + b * n) >= rh - 2.1;
      }
      if (clear) spots.emplace_back(p, std::atan2(t.y(), t.x()) + (side > 0 ? M_PI : 0.0));
    }
  }
  std::vector<Vector2d> cars = ParkedCarCentres(world);
  int placed = 0;
  for (int attempt = 0; attempt < 50 * count && placed < count && !spots.empty(); ++attempt) {
    const auto& [p, heading] = spots[rng() % spots.size()];
    const double jitter = Uniform(rng, -0.04, 0.04);
    const int style = static_cast<int>(rng() % 100000u);
    bool free = true;  // 4.3 m long cars, at least 0.9 m apart
    for (const auto& other : cars) free = free && (other - p).norm() >= 5.2;
    if (!free) continue;
    AddParkedCar(world, p, heading + jitter, style);
    cars.push_back(p);
    ++placed;
  }
  return placed;
}

// Draws up to `count` free-standing buildings (no neighbour is left open) with a wall near the
// drive and labels their planes removed; returns which quads of `town` are gone now.
std::vector<bool> RemoveBuildings(const World& town,
                                  const std::map<int, std::vector<int>>& buildings,
                                  const std::vector<Vector3d>& camera_centres, int count,
                                  std::mt19937& rng, ChangedWorld* out) {
  std::vector<int> candidates;  // building (style) indices
  for (const auto& [building, facades] : buildings) {
    if (!FreeStanding(town, facades)) continue;
    for (const int i : facades) {
      if (QuadNearDrive(town.quads[static_cast<std::size_t>(i)], camera_centres)) {
        candidates.push_back(building);
        break;
      }
    }
  }
  std::vector<bool> gone(town.quads.size(), false);
  const std::vector<int> removed = PickIndices(static_cast<int>(candidates.size()), count, rng);
  for (const int c : removed) {
    for (const int i : buildings.at(candidates[static_cast<std::size_t>(c)])) {
      gone[static_cast<std::size_t>(i)] = true;
      out->labels[static_cast<std::size_t>(town.quads[static_cast<std::size_t>(i)].plane_id)]
          .change = PlaneChange::kRemoved;
    }
  }
  out->counts.removed_buildings = static_cast<int>(removed.size());
  return gone;
}

// Renovation: moves a share of the ground-level facades (fronts, and side walls shared with no
// neighbour) near the drive of the buildings that stay, in `out->now`, and labels them.
void MoveFacades(const World& town, const std::map<int, std::vector<int>>& buildings,
                 const std::vector<bool>& gone, const std::vector<Vector3d>& camera_centres,
                 const WorldChangesOptions& options, std::mt19937& rng, ChangedWorld* out) {
  std::vector<std::pair<int, int>> facades;  // (building, quad)
  for (const auto& [building, walls] : buildings) {
    for (const int i : walls) {
      const Quad& quad = town.quads[static_cast<std::size_t>(i)];
      if (!gone[static_cast<std::size_t>(i)] && std::abs(quad.origin.z()) < 1e-9 &&
          QuadNearDrive(quad, camera_centres)) {
        facades.emplace_back(building, i);
      }
    }
  }
  const int count =
      static_cast<int>(std::lround(options.moved_fraction * static_cast<double>(facades.size())));
  for (const int f : PickIndices(static_cast<int>(facades.size()), count, rng)) {
    const auto [building, quad] = facades[static_cast<std::size_t>(f)];
    const double magnitude = Uniform(rng, options.min_offset, options.max_offset);
    const double offset = (rng() & 1u) != 0 ? magnitude : -magnitude;
    MoveFacade(out->now, quad, buildings.at(building), offset);
    PlaneChangeLabel& label =
        out->labels[static_cast<std::size_t>(town.quads[static_cast<std::size_t>(quad)].plane_id)];
    label.change = PlaneChange::kMoved;
    label.offset_m = offset;
    ++out->counts.moved_facades;
  }
}

}  // namespace

std::string WorldChangesOptions::ToSpec() const {
  if (!Any()) return "none";
  std::vector<std::string> items;
  if (moved_fraction > 0.0) {
    items.push_back(fmt::format("moved={}", moved_fraction));
    items.push_back(fmt::format("offset={}:{}", min_offset, max_offset));
  }
  if (removed_buildings > 0) items.push_back(fmt::format("removed={}", removed_buildings));
  if (new_walls > 0) items.push_back(fmt::format("new={}", new_walls));
  if (parked_cars > 0) items.push_back(fmt::format("cars={}", parked_cars));
  std::string spec;
  for (const std::string& item : items) spec += (spec.empty() ? "" : ",") + item;
  return spec;
}

void WorldChangesOptions::Check() const {
  const std::string spec = ToSpec();
  if (!(moved_fraction >= 0.0 && moved_fraction <= 1.0)) FailSpec(spec, "moved is not in 0..1");
  if (!(min_offset > 0.0 && min_offset <= max_offset && max_offset <= kMaxOffset)) {
    FailSpec(spec, "offset is not MIN:MAX with 0 < MIN <= MAX <= 2");
  }
  for (const int count : {removed_buildings, new_walls, parked_cars}) {
    if (count < 0 || count > kMaxCount) FailSpec(spec, "a count is not in 0..100");
  }
}

WorldChangesOptions ParseWorldChanges(const std::string& spec) {
  if (spec == "renovation") return Renovation();
  if (spec == "none") return {};
  if (spec.empty()) FailSpec("''", "the spec is empty");
  WorldChangesOptions options;
  std::vector<std::string> seen;
  for (const std::string& item : Split(spec, ',')) {
    const std::size_t equals = item.find('=');
    if (equals == std::string::npos) FailSpec(spec, fmt::format("'{}' is not KEY=VALUE", item));
    const std::string key = item.substr(0, equals), value = item.substr(equals + 1);
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
      FailSpec(spec, fmt::format("'{}' is given twice", key));
    }
    seen.push_back(key);
    if (key == "moved") {
      if (!ParseDouble(value, &options.moved_fraction) || options.moved_fraction < 0.0 ||
          options.moved_fraction > 1.0) {
        FailSpec(spec, fmt::format("moved '{}' is not a fraction in 0..1", value));
      }
    } else if (key == "offset") {
      const std::vector<std::string> range = Split(value, ':');
      if (range.size() != 2 || !ParseDouble(range[0], &options.min_offset) ||
          !ParseDouble(range[1], &options.max_offset) || !(options.min_offset > 0.0) ||
          options.min_offset > options.max_offset || options.max_offset > kMaxOffset) {
        FailSpec(spec,
                 fmt::format("offset '{}' is not MIN:MAX metres with 0 < MIN <= MAX <= 2", value));
      }
    } else if (key == "removed" || key == "new" || key == "cars") {
      int* count = key == "removed" ? &options.removed_buildings
                   : key == "new"   ? &options.new_walls
                                    : &options.parked_cars;
      if (!ParseCount(value, count)) {
        FailSpec(spec, fmt::format("{} '{}' is not a whole number in 0..100", key, value));
      }
    } else {
      FailSpec(spec, fmt::format("unknown key '{}'", key));
    }
  }
  return options;
}

const char* PlaneChangeName(PlaneChange change) {
  switch (change) {
    case PlaneChange::kUnchanged:
      return "unchanged";
    case PlaneChange::kMoved:
      return "moved";
    case PlaneChange::kRemoved:
      return "removed";
    case PlaneChange::kNew:
      return "new";
  }
  return "unchanged";
}

ChangedWorld ApplyWorldChanges(const World& town, const StreetPath& street,
                               const std::vector<Eigen::Vector3d>& camera_centres,
                               const WorldChangesOptions& options, std::uint32_t seed,
                               const TownOptions& town_options) {
  options.Check();
  ChangedWorld out;
  out.at_mapping = town;
  out.now = town;
  out.labels.assign(town.planes.size(), PlaneChangeLabel{});
  const auto stream = [&](Stream kind) {
    return std::mt19937(HashCombine(seed, kChangesStream, static_cast<std::uint32_t>(kind)));
  };
  const std::map<int, std::vector<int>> buildings = FacadesByBuilding(town);

  std::mt19937 removed_rng = stream(kRemovedStream);
  const std::vector<bool> gone = RemoveBuildings(town, buildings, camera_centres,
                                                 options.removed_buildings, removed_rng, &out);
  std::mt19937 moved_rng = stream(kMovedStream);
  MoveFacades(town, buildings, gone, camera_centres, options, moved_rng, &out);
  // Removed quads leave `now` last, so the quad indices stay valid while moving facades.
  std::vector<Quad> quads_now;
  for (std::size_t i = 0; i < out.now.quads.size(); ++i) {
    if (i >= gone.size() || !gone[i]) quads_now.push_back(out.now.quads[i]);  // steps are added
  }
  out.now.quads = std::move(quads_now);

  // New walls: beside the street where the cameras pass, between the buildings of both times.
  std::vector<Station> stations;
  for (double s = 0.0; s < street.length(); s += 2.0) {
    for (const int side : {1, -1}) {
      const Vector2d p = street.Position(s) + side * 10.0 * LeftNormal(street.Tangent(s));
      if (HorizontalDistanceToDrive(p, camera_centres) <= kSiteReach) stations.push_back({s, side});
    }
  }
  std::mt19937 wall_rng = stream(kNewWallStream);
  for (int w = 0; w < options.new_walls; ++w) {
    if (!AddNewWall(out.now, street, stations, town_options, wall_rng)) break;
    out.labels.push_back({PlaneChange::kNew, 0.0});
    ++out.counts.new_walls;
  }

  std::mt19937 car_rng = stream(kCarStream);
  out.counts.parked_cars = AddParkedCars(out.at_mapping, street, camera_centres, town_options,
                                         options.parked_cars, car_rng);
  return out;
}

}  // namespace planeloc::sim
