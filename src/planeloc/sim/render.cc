#include "planeloc/sim/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

constexpr float kPi = 3.14159265358979f;

// Sky radiance: bright near the horizon, a little darker overhead (KITTI skies are near white).
float Sky(const Eigen::Vector3f& dir) { return 0.98f - 0.22f * std::max(dir.z(), 0.0f); }

// Nothing in the town is taller than 30 m, so a shadow ray that has climbed that high is free:
// bounding it keeps shadow rays cheap.
float ShadowReach(const Eigen::Vector3f& to_sun) { return 30.0f / std::max(to_sun.z(), 0.1f); }

}  // namespace

FrameLighting LightingForFrame(Lighting mode, std::uint32_t seed, int frame) {
  FrameLighting light;
  std::mt19937 rng(HashCombine(seed, 0x11647u));
  std::uniform_real_distribution<float> phase(0.0f, 2.0f * kPi);
  const float azimuth0 = phase(rng), p1 = phase(rng), p2 = phase(rng), p3 = phase(rng);
  const float elevation = 0.75f;  // ~43 degrees
  float azimuth = azimuth0;
  if (mode == Lighting::kChanging) {
    const float t = static_cast<float>(frame);
    azimuth += 1.75f * t / 1000.0f;
    light.exposure = 1.0f + 0.22f * std::sin(2.0f * kPi * t / 420.0f + p1) +
                     0.08f * std::sin(2.0f * kPi * t / 67.0f + p2);
    // Clouds: the direct light dims for a few seconds at a time.
    const float cloud = 0.5f + 0.5f * std::sin(2.0f * kPi * t / 180.0f + p3);
    light.sun = 0.65f * (1.0f - 0.7f * cloud * cloud * cloud);
    light.ambient = 0.45f;
    light.shadows = true;
  }
  light.to_sun = Eigen::Vector3f(std::cos(elevation) * std::cos(azimuth),
                                 std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  return light;
}

void CameraRenderOptions::Check() const {
  if (supersampling < 1 || supersampling > 8) throw OptionsError("supersampling must be in [1, 8]");
  if (!(noise_sigma >= 0.0f)) throw OptionsError("noise_sigma must be >= 0");
  if (!distortion.allFinite() || distortion.cwiseAbs().maxCoeff() > 2.0) {
    throw OptionsError("distortion coefficients must be finite and within [-2, 2]");
  }
}

void LidarOptions::Check() const {
  if (beams < 1) throw OptionsError("LidarOptions.beams must be >= 1");
  if (azimuth_steps < 1) throw OptionsError("LidarOptions.azimuth_steps must be >= 1");
  if (!(max_range > min_range && min_range >= 0.0)) throw OptionsError("LidarOptions: bad range");
  if (!(range_noise >= 0.0)) throw OptionsError("LidarOptions.range_noise must be >= 0");
}

namespace {

// Radiance of one camera ray (sky or lit surface); `spacing` = footprint per metre of distance.
struct RayShader {
  const Scene& scene;
  const Shader& shader;
  const FrameLighting& light;

  float Surface(const Hit& hit, const Eigen::Vector3f& origin, const Eigen::Vector3f& dir,
                float spacing) const {
    const Eigen::Vector3f point = origin + hit.t * dir;
    const float cosine = std::max(-hit.normal.dot(dir), 0.02f);
    // Geometric mean of the footprint's two axes (t*s and t*s/cos): trilinear filtering that
    // neither blurs grazing road too much nor lets it alias.
    const float footprint = hit.t * spacing / std::sqrt(cosine);
    const float albedo = shader.Albedo(hit, point, footprint);
    float direct = std::max(hit.normal.dot(light.to_sun), 0.0f) * light.sun;
    if (light.shadows && direct > 0.0f &&
        scene.Occluded(point + 0.02f * hit.normal, light.to_sun, ShadowReach(light.to_sun))) {
      direct = 0.0f;
    }
    return albedo * (light.ambient + direct);
  }
  float Trace(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float spacing) const {
    Hit hit;
    if (!scene.Intersect(origin, dir, 1e4f, &hit)) return Sky(dir);
    return Surface(hit, origin, dir, spacing);
  }
};

// A raw pixel position -> the unit ray through it in the view's frame. With distortion the
// normalized point is found by Newton's method on OpenCV's radial-tangential model (the model the
// rectifier inverts), which converges in a few steps where fixed-point iteration is slow at the
// corners of a wide, strongly distorted lens such as EuRoC's.
class PixelRays {
 public:
  PixelRays(const StereoCamera& camera, const Eigen::Vector4d& distortion)
      : inv_fx_(1.0f / static_cast<float>(camera.fx)),
        inv_fy_(1.0f / static_cast<float>(camera.fy)),
        cx_(static_cast<float>(camera.cx)),
        cy_(static_cast<float>(camera.cy)),
        k_(distortion),
        distorted_(!distortion.isZero(0.0)) {}

  Eigen::Vector3f operator()(float px, float py) const {
    if (!distorted_) {
      return Eigen::Vector3f((px - cx_) * inv_fx_, (py - cy_) * inv_fy_, 1.0f).normalized();
    }
    const double xd = (px - cx_) * static_cast<double>(inv_fx_);
    const double yd = (py - cy_) * static_cast<double>(inv_fy_);
    const double k1 = k_[0], k2 = k_[1], p1 = k_[2], p2 = k_[3];
    double x = xd, y = yd;
    for (int iteration = 0; iteration < 8; ++iteration) {
      const double r2 = x * x + y * y;
      const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
      const double dradial = 2.0 * (k1 + 2.0 * k2 * r2);  // d radial / d(x or y), over x or y
      const double ex = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) - xd;
      const double ey = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y - yd;
      const double jxx = radial + x * x * dradial + 2.0 * p1 * y + 6.0 * p2 * x;
      const double jxy = x * y * dradial + 2.0 * p1 * x + 2.0 * p2 * y;
      const double jyy = radial + y * y * dradial + 6.0 * p1 * y + 2.0 * p2 * x;
      const double det = jxx * jyy - jxy * jxy;
      if (std::abs(det) < 1e-12) break;
      const double step_x = (jyy * ex - jxy * ey) / det, step_y = (jxx * ey - jxy * ex) / det;
      x -= step_x;
      y -= step_y;
      if (std::abs(step_x) + std::abs(step_y) < 1e-12) break;
    }
    return Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), 1.0f).normalized();
  }

 private:
  float inv_fx_, inv_fy_, cx_, cy_;
  Eigen::Vector4d k_;
  bool distorted_;
};

// Identifies what a pixel-centre ray hit: -1 for sky, else kind and index.
std::int64_t HitKey(bool found, const Hit& hit) {
  if (!found) return -1;
  return (static_cast<std::int64_t>(hit.kind) << 32) | hit.index;
}

}  // namespace

cv::Mat RenderView(const Scene& scene, const Shader& shader, const StereoCamera& camera,
                   const Rigid3d& world_from_view, const FrameLighting& light,
                   std::uint32_t noise_seed, const CameraRenderOptions& options) {
  options.Check();
  const int width = camera.width, height = camera.height;
  cv::Mat image(height, width, CV_8UC1);
  const Eigen::Matrix3f rotation = world_from_view.RotationMatrix().cast<float>();
  const Eigen::Vector3f origin = world_from_view.translation.cast<float>();
  const int ss = options.supersampling;
  const float inv_fx = 1.0f / static_cast<float>(camera.fx);
  const PixelRays pixel_rays(camera, options.distortion);
  auto ray = [&](float px, float py) { return Eigen::Vector3f(rotation * pixel_rays(px, py)); };
  const RayShader tracer{scene, shader, light};
  // Pass 1: one ray through every pixel centre; only what it hit is kept (8 bytes a pixel).
  std::vector<std::int64_t> key(static_cast<std::size_t>(width) * height);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      Hit previous;
      bool hinted = false;  // the previous pixel's surface, usually this one's too
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * width + x;
        Hit hit;
        const bool found =
            scene.Intersect(origin, ray(x, y), 1e4f, &hit, hinted ? &previous : nullptr);
        key[i] = HitKey(found, hit);
        hinted = found;
        if (found) previous = hit;
      }
    }
  });
  // Pass 2: pixels whose 4-neighbours saw the same surface are shaded once with the whole pixel
  // as texture footprint (the mip filter is the area average); pixels at a surface boundary get
  // ss x ss supersampling (adaptive antialiasing: same result, a third of the rays).
  const float inv_samples = 1.0f / static_cast<float>(ss * ss);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      std::mt19937 rng(HashCombine(noise_seed, static_cast<std::uint32_t>(y)));
      std::normal_distribution<float> noise(0.0f, options.noise_sigma);
      std::uint8_t* out = image.ptr<std::uint8_t>(y);
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * width + x;
        // A surface boundary between this pixel's centre and a 4-neighbour's crosses the pixel.
        bool uniform = ss == 1;
        if (!uniform) {
          const std::int64_t k = key[i];
          uniform = (x == 0 || key[i - 1] == k) && (x + 1 == width || key[i + 1] == k) &&
                    (y == 0 || key[i - width] == k) && (y + 1 == height || key[i + width] == k);
        }
        float radiance = 0.0f;
        Hit hit;
        const Eigen::Vector3f dir = ray(x, y);
        if (uniform && key[i] < 0) {
          radiance = Sky(dir);
        } else if (uniform &&
                   scene.IntersectOne(static_cast<PrimitiveKind>(key[i] >> 32),
                                      static_cast<std::uint32_t>(key[i]), origin, dir, &hit)) {
          radiance = tracer.Surface(hit, origin, dir, inv_fx);
        } else {
          for (int sy = 0; sy < ss; ++sy) {
            for (int sx = 0; sx < ss; ++sx) {
              const float px = x + (sx + 0.5f) / ss - 0.5f, py = y + (sy + 0.5f) / ss - 0.5f;
              radiance += tracer.Trace(origin, ray(px, py), inv_fx / ss);
            }
          }
          radiance *= inv_samples;
        }
        const float value = 255.0f * light.exposure * radiance + noise(rng);
        out[x] = static_cast<std::uint8_t>(std::clamp(std::lround(value), 0l, 255l));
      }
    }
  });
  return image;
}

cv::Mat RenderViewDuringExposure(const Scene& scene, const Shader& shader,
                                 const StereoCamera& camera, const Rigid3d& world_from_view_open,
                                 const Rigid3d& world_from_view_close, const FrameLighting& light,
                                 std::uint32_t noise_seed, const CameraRenderOptions& options) {
  options.Check();
  const int width = camera.width, height = camera.height;
  const int ss = options.supersampling, samples = ss * ss;
  // One pose per sample time, (k + 0.5) / samples through the exposure.
  std::vector<Eigen::Matrix3f> rotations;
  std::vector<Eigen::Vector3f> origins;
  for (int k = 0; k < samples; ++k) {
    const double tau = (k + 0.5) / samples;
    rotations.push_back(world_from_view_open.rotation.slerp(tau, world_from_view_close.rotation)
                            .toRotationMatrix()
                            .cast<float>());
    origins.push_back(
        ((1.0 - tau) * world_from_view_open.translation + tau * world_from_view_close.translation)
            .cast<float>());
  }
  const PixelRays pixel_rays(camera, options.distortion);
  const float footprint = 1.0f / static_cast<float>(camera.fx) / static_cast<float>(ss);
  const RayShader tracer{scene, shader, light};
  cv::Mat image(height, width, CV_8UC1);
  const float inv_samples = 1.0f / static_cast<float>(samples);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      std::mt19937 rng(HashCombine(noise_seed, static_cast<std::uint32_t>(y)));
      std::normal_distribution<float> noise(0.0f, options.noise_sigma);
      std::uint8_t* out = image.ptr<std::uint8_t>(y);
      for (int x = 0; x < width; ++x) {
        float radiance = 0.0f;
        // Sample positions and times are paired differently from pixel to pixel, so the blur
        // carries no fixed pattern.
        const int shift = (x + 2 * y) % samples;
        for (int sy = 0; sy < ss; ++sy) {
          for (int sx = 0; sx < ss; ++sx) {
            const int k = (sx + ss * sy + shift) % samples;
            const float px = x + (sx + 0.5f) / ss - 0.5f, py = y + (sy + 0.5f) / ss - 0.5f;
            const Eigen::Vector3f dir = rotations[k] * pixel_rays(px, py);
            radiance += tracer.Trace(origins[k], dir, footprint);
          }
        }
        const float value = 255.0f * light.exposure * radiance * inv_samples + noise(rng);
        out[x] = static_cast<std::uint8_t>(std::clamp(std::lround(value), 0l, 255l));
      }
    }
  });
  return image;
}

VelodyneScan ScanLidar(const Scene& scene, const Shader& shader, const Rigid3d& world_from_velo,
                       std::uint32_t noise_seed, const LidarOptions& options) {
  options.Check();
  const Eigen::Matrix3f rotation = world_from_velo.RotationMatrix().cast<float>();
  const Eigen::Vector3f origin = world_from_velo.translation.cast<float>();
  std::vector<VelodyneScan> per_beam(static_cast<std::size_t>(options.beams));
  tbb::parallel_for(0, options.beams, [&](int beam) {
    std::mt19937 rng(HashCombine(noise_seed, static_cast<std::uint32_t>(beam)));
    std::normal_distribution<double> noise(0.0, options.range_noise);
    const double elevation =
        options.beams == 1
            ? options.max_elevation_deg
            : options.max_elevation_deg - (options.max_elevation_deg - options.min_elevation_deg) *
                                              beam / (options.beams - 1);
    const double el = elevation * M_PI / 180.0;
    VelodyneScan& out = per_beam[static_cast<std::size_t>(beam)];
    out.points.reserve(static_cast<std::size_t>(options.azimuth_steps));
    Hit previous;
    bool hinted = false;
    for (int step = 0; step < options.azimuth_steps; ++step) {
      const double az = -M_PI + 2.0 * M_PI * step / options.azimuth_steps;
      const Eigen::Vector3d dir_velo(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                     std::sin(el));
      const Eigen::Vector3f dir = rotation * dir_velo.cast<float>();
      Hit hit;
      // Draw the noise for every beam direction so one lost return never shifts the others.
      const double range_noise = noise(rng);
      const bool found = scene.Intersect(origin, dir, static_cast<float>(options.max_range), &hit,
                                         hinted ? &previous : nullptr);
      hinted = found;  // the next azimuth step usually hits the same surface
      if (!found) continue;
      previous = hit;
      if (hit.t < options.min_range) continue;
      const Eigen::Vector3f point = origin + hit.t * dir;
      out.points.push_back(dir_velo * (static_cast<double>(hit.t) + range_noise));
      out.reflectance.push_back(shader.Reflectance(hit, point, dir));
    }
  });
  VelodyneScan scan;
  for (auto& beam : per_beam) {
    scan.points.insert(scan.points.end(), beam.points.begin(), beam.points.end());
    scan.reflectance.insert(scan.reflectance.end(), beam.reflectance.begin(),
                            beam.reflectance.end());
  }
  return scan;
}

}  // namespace planeloc::sim
