// The indoor preset (issue 35): a Vicon-room-like space with furniture and clutter, a drone's
// 6-DoF flight through it, and the stations of a static survey scanner. W is z up with the floor
// at z = 0 and the room centred on the origin; the GT planes are the floor, ceiling, walls and the
// large faces of the furniture.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "planeloc/geometry/rigid3.h"
#include "planeloc/sim/world.h"

namespace planeloc::sim {

struct RoomOptions {
  double length = 8.0;  // metres along x
  double width = 8.0;   // metres along y
  double height = 4.0;  // metres
  bool clutter = true;  // boxes, balls and bins besides the furniture
  void Check() const;   // throws OptionsError
};

// Walls, floor and ceiling, cabinets and shelves along the walls, tables, and clutter, all within
// 1.1 m of the walls so that RoomFlightSpace stays free. Fully determined by the seed.
World BuildRoom(std::uint32_t seed, const RoomOptions& options = {});

// Where the camera may fly: 1.5 m clear of the walls (so >= 0.4 m from any furniture), between
// 0.7 m above the floor and 1.2 m below the ceiling.
Eigen::AlignedBox3d RoomFlightSpace(const RoomOptions& options);

// Three survey-scanner stations at tripod height inside the flight space, as a room is surveyed.
std::vector<Eigen::Vector3d> RoomSurveyStations(const RoomOptions& options);

struct FlightOptions {
  double mean_speed = 0.7;        // m/s, about EuRoC V1_02's (0.9) and V1_01's (0.4)
  double peak_yaw_rate_deg = 80;  // deg/s, the fastest turns (EuRoC "difficult": ~100)
  double tilt_deg = 15.0;         // pitch and roll amplitude
  void Check() const;             // throws OptionsError
};

// A smooth hand-held / drone flight inside RoomFlightSpace: position and heading from sums of
// sinusoids with seeded phases, the camera looking roughly horizontally (slightly down).
class RoomFlight {
 public:
  RoomFlight(const RoomOptions& room, const FlightOptions& flight, std::uint32_t seed);
  // world_from_cam (camera axes: x right, y down, z forward) at `t` seconds.
  Rigid3d WorldFromCamAt(double t) const;

 private:
  Eigen::Vector3d centre_, amplitude_;
  double phase_[3][2] = {};
  double omega_[3][2] = {};
  double yaw0_ = 0.0, yaw_drift_ = 0.0;
  double yaw_amp_[2] = {}, yaw_omega_[2] = {}, yaw_phase_[2] = {};
  double tilt_ = 0.0, tilt_phase_[2] = {};
};

}  // namespace planeloc::sim
