// The simulated sensors: a pinhole camera rendered by ray casting (2x2 supersampling, footprint-
// filtered textures, sun + sky lighting, optional cast shadows, Gaussian pixel noise) and an
// HDL-64E-like spinning LiDAR. Both parallelize with TBB over rows / beams and draw their noise
// from std::mt19937 streams seeded per (seed, row/beam), so the output bytes never depend on the
// thread count.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/sim/raycast.h"
#include "planeloc/sim/shading.h"
#include "planeloc/sim/simulator.h"

namespace planeloc::sim {

struct FrameLighting {
  Eigen::Vector3f to_sun = Eigen::Vector3f(0.5f, 0.3f, 0.81f).normalized();  // unit, in W
  float sun = 0.55f;      // direct light on a surface facing the sun
  float ambient = 0.5f;   // sky light
  float exposure = 1.0f;  // camera gain multiplying the radiance
  bool shadows = false;   // cast shadow rays toward the sun
};

// Lighting of frame `frame` (10 Hz): constant, or slowly drifting exposure, a sun that turns
// through ~100 degrees of azimuth over 1 000 frames, passing clouds, and cast shadows.
FrameLighting LightingForFrame(Lighting mode, std::uint32_t seed, int frame);

struct CameraRenderOptions {
  int supersampling = 2;     // samples per pixel along each axis
  float noise_sigma = 2.0f;  // grey levels, Gaussian, added after quantization-free shading
  // Radial-tangential k1 k2 p1 p2 (OpenCV's model, EuRoC's cameras) of the raw image; zero is an
  // ideal pinhole (the rectified KITTI-like views).
  Eigen::Vector4d distortion = Eigen::Vector4d::Zero();
  void Check() const;
};

// Renders one grey 8-bit view (CV_8UC1, camera.width x camera.height) of the scene seen from
// `world_from_view` (KITTI camera axes: x right, y down, z forward) with the intrinsics of
// `camera`.
cv::Mat RenderView(const Scene& scene, const Shader& shader, const StereoCamera& camera,
                   const Rigid3d& world_from_view, const FrameLighting& lighting,
                   std::uint32_t noise_seed, const CameraRenderOptions& options = {});

// The same view with motion blur: every pixel takes supersampling^2 samples, each at its own time
// in the exposure (the pose interpolated between the shutter's opening and closing), so a camera
// that moves by pixels during the exposure smears the image as a real one does.
cv::Mat RenderViewDuringExposure(const Scene& scene, const Shader& shader,
                                 const StereoCamera& camera, const Rigid3d& world_from_view_open,
                                 const Rigid3d& world_from_view_close,
                                 const FrameLighting& lighting, std::uint32_t noise_seed,
                                 const CameraRenderOptions& options = {});

struct LidarOptions {
  int beams = 64;
  double max_elevation_deg = 2.0;
  double min_elevation_deg = -24.8;
  int azimuth_steps = 2250;   // per revolution (0.16 degrees)
  double max_range = 120.0;   // metres
  double min_range = 2.0;     // metres; closer returns are dropped, as the HDL-64E does
  double range_noise = 0.02;  // metres, Gaussian sigma along the beam
  void Check() const;
};

// One full revolution from `world_from_velo` (x forward, y left, z up), points in the velodyne
// frame ordered beam by beam (top beam first), each beam by azimuth from -180 degrees.
VelodyneScan ScanLidar(const Scene& scene, const Shader& shader, const Rigid3d& world_from_velo,
                       std::uint32_t noise_seed, const LidarOptions& options = {});

}  // namespace planeloc::sim
