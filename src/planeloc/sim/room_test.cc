#include "planeloc/sim/room.h"

#include <gtest/gtest.h>

#include <cmath>

#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

double DistanceToBox(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& point) {
  return std::sqrt(box.squaredExteriorDistance(point));
}

TEST(RoomTest, WallsFloorAndCeilingAreGtPlanesAndTheFurnitureLeavesTheFlightSpaceFree) {
  const RoomOptions options;
  const World world = BuildRoom(7, options);
  int ground = 0, facade = 0, other = 0;
  for (const GtPlane& plane : world.planes) {
    ground += plane.kind == "ground";
    facade += plane.kind == "facade";
    other += plane.kind == "other";
  }
  EXPECT_EQ(ground, 1);
  EXPECT_GE(facade, 4 + 3);  // the walls and at least a few furniture fronts and sides
  EXPECT_GE(other, 1 + 1);   // the ceiling and at least one table or cabinet top
  // The shell's normals face the room's middle; furniture faces point up or away from the wall they
  // stand against (fronts into the room, sides along the wall), never into the wall.
  const Eigen::Vector3d middle(0, 0, 1.5);
  for (const GtPlane& plane : world.planes) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& corner : plane.polygon) centroid += corner / plane.polygon.size();
    const bool shell = std::abs(centroid.z()) < 1e-9 || std::abs(centroid.z() - 4.0) < 1e-9 ||
                       std::abs(std::abs(centroid.x()) - 4.0) < 1e-9 ||
                       std::abs(std::abs(centroid.y()) - 4.0) < 1e-9;
    if (shell) {
      EXPECT_GT(plane.plane.SignedDistance(middle), 1.0) << plane.id;
      continue;
    }
    const Eigen::Vector3d from_wall =
        std::abs(centroid.x()) > std::abs(centroid.y())
            ? Eigen::Vector3d(-std::copysign(1.0, centroid.x()), 0, 0)
            : Eigen::Vector3d(0, -std::copysign(1.0, centroid.y()), 0);
    EXPECT_GT(plane.plane.normal.dot(from_wall) + plane.plane.normal.z(), -1e-9)
        << plane.id << " " << plane.kind << ": " << plane.plane.normal.transpose();
  }
  // Nothing but the room's shell comes within 0.4 m of where the camera flies.
  const Eigen::AlignedBox3d space = RoomFlightSpace(options);
  for (std::size_t i = 0; i < world.quads.size(); ++i) {
    for (const Eigen::Vector3d& corner : world.quads[i].Corners()) {
      EXPECT_GT(DistanceToBox(space, corner), 0.4) << "quad " << i;
    }
  }
  for (const Cylinder& c : world.cylinders) {
    EXPECT_GT(DistanceToBox(space, c.base) - c.radius, 0.4);
  }
  for (const Sphere& s : world.spheres) {
    EXPECT_GT(DistanceToBox(space, s.center) - s.radius, 0.4);
  }
}

TEST(RoomTest, TheSeedDecidesTheRoom) {
  const World a = BuildRoom(3), b = BuildRoom(3), c = BuildRoom(4);
  ASSERT_EQ(a.quads.size(), b.quads.size());
  for (std::size_t i = 0; i < a.quads.size(); ++i) {
    EXPECT_EQ(a.quads[i].origin, b.quads[i].origin);
    EXPECT_EQ(a.quads[i].style, b.quads[i].style);
  }
  bool differs = a.quads.size() != c.quads.size();
  for (std::size_t i = 6; !differs && i < a.quads.size(); ++i) {
    differs = a.quads[i].origin != c.quads[i].origin;
  }
  EXPECT_TRUE(differs);
}

// 60 s of flight at 20 Hz: inside the flight space, at the requested mean speed, with turns as fast
// as asked and no faster, never closer than 0.4 m to a surface.
TEST(RoomTest, FlightStaysInsideAtTheRequestedSpeedAndTurnRate) {
  const RoomOptions room;
  const FlightOptions flight_options;  // 0.7 m/s, 80 deg/s peak
  const World world = BuildRoom(5, room);
  const Eigen::AlignedBox3d space = RoomFlightSpace(room);
  for (const std::uint32_t seed : {1u, 2u, 9u}) {
    const RoomFlight flight(room, flight_options, seed);
    const double dt = 0.05;
    double distance = 0.0, peak_yaw_rate = 0.0, closest = 1e9;
    Rigid3d previous = flight.WorldFromCamAt(0.0);
    for (int i = 1; i <= 1200; ++i) {
      const Rigid3d pose = flight.WorldFromCamAt(i * dt);
      EXPECT_TRUE(space.contains(pose.translation)) << i << ": " << pose.translation.transpose();
      distance += (pose.translation - previous.translation).norm();
      // Yaw of the optical axis about the vertical.
      const Eigen::Vector3d f0 = previous.RotationMatrix().col(2),
                            f1 = pose.RotationMatrix().col(2);
      const double yaw_step =
          std::remainder(std::atan2(f1.y(), f1.x()) - std::atan2(f0.y(), f0.x()), 2.0 * M_PI);
      peak_yaw_rate = std::max(peak_yaw_rate, std::abs(yaw_step) / dt * 180.0 / M_PI);
      // The camera looks roughly level: never more than 35 degrees up or down.
      EXPECT_LT(std::abs(f1.z()), std::sin(35.0 * M_PI / 180.0));
      if (i % 10 == 0) closest = std::min(closest, world.DistanceToSurface(pose.translation));
      previous = pose;
    }
    const double mean_speed = distance / 60.0;
    // Measured 0.69-0.72 m/s, 78.5-80.0 deg/s and 0.72-0.93 m over these seeds.
    EXPECT_NEAR(mean_speed, flight_options.mean_speed, 0.2 * flight_options.mean_speed) << seed;
    EXPECT_GT(peak_yaw_rate, 0.6 * flight_options.peak_yaw_rate_deg) << seed;
    EXPECT_LE(peak_yaw_rate, 1.01 * flight_options.peak_yaw_rate_deg) << seed;
    EXPECT_GT(closest, 0.4) << seed;
  }
}

TEST(RoomTest, OptionsAreChecked) {
  RoomOptions small;
  small.length = 3.0;
  EXPECT_THROW(small.Check(), OptionsError);
  FlightOptions fast;
  fast.mean_speed = 0.0;
  EXPECT_THROW(fast.Check(), OptionsError);
  FlightOptions tilted;
  tilted.tilt_deg = 60.0;
  EXPECT_THROW(tilted.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc::sim
