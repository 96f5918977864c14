#include "planeloc/sim/texture.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

float Smooth(float t) { return t * t * (3.0f - 2.0f * t); }

// Tileable value noise: a `cells` x `cells` random lattice over size x size texels.
cv::Mat ValueNoise(int size, int cells, std::mt19937& rng) {
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<float> lattice(static_cast<std::size_t>(cells) * cells);
  for (auto& value : lattice) value = uniform(rng);
  cv::Mat out(size, size, CV_32F);
  const float scale = static_cast<float>(cells) / static_cast<float>(size);
  for (int y = 0; y < size; ++y) {
    const float fy = y * scale;
    const int y0 = static_cast<int>(fy), y1 = (y0 + 1) % cells;
    const float ty = Smooth(fy - static_cast<float>(y0));
    float* row = out.ptr<float>(y);
    for (int x = 0; x < size; ++x) {
      const float fx = x * scale;
      const int x0 = static_cast<int>(fx), x1 = (x0 + 1) % cells;
      const float tx = Smooth(fx - static_cast<float>(x0));
      const float a = lattice[y0 * cells + x0], b = lattice[y0 * cells + x1];
      const float c = lattice[y1 * cells + x0], d = lattice[y1 * cells + x1];
      row[x] = (a + (b - a) * tx) * (1.0f - ty) + (c + (d - c) * tx) * ty;
    }
  }
  return out;
}

// Fractal sum of value noise, octaves doubling the lattice; result roughly in [0, 1], mean 0.5.
cv::Mat Fbm(int size, int base_cells, int octaves, float gain, std::mt19937& rng) {
  cv::Mat sum = cv::Mat::zeros(size, size, CV_32F);
  float amplitude = 1.0f, total = 0.0f;
  for (int o = 0, cells = base_cells; o < octaves && cells <= size; ++o, cells *= 2) {
    sum += amplitude * ValueNoise(size, cells, rng);
    total += amplitude;
    amplitude *= gain;
  }
  return sum / total;
}

// Calls `draw(offset)` for the 9 copies of a shape so shapes crossing a border wrap around.
void DrawWrapped(int size, const std::function<void(cv::Point)>& draw) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) draw(cv::Point(dx * size, dy * size));
  }
}

// Speckles: `count` dots of radius 1..max_radius with albedo offsets in [-amp, amp].
void AddSpeckles(cv::Mat& tex, int count, int max_radius, float amp, std::mt19937& rng) {
  std::uniform_int_distribution<int> pos(0, tex.cols - 1), radius(1, max_radius);
  std::uniform_real_distribution<float> value(-amp, amp);
  cv::Mat delta = cv::Mat::zeros(tex.size(), CV_32F);
  for (int i = 0; i < count; ++i) {
    const cv::Point c(pos(rng), pos(rng));
    const int r = radius(rng);
    const float v = value(rng);
    DrawWrapped(tex.cols, [&](cv::Point o) { cv::circle(delta, c + o, r, cv::Scalar(v), -1); });
  }
  tex += delta;
}

// Rectangular units (bricks, slabs, panels) of w x h texels with `joint` texels of mortar,
// rows shifted by `stagger` texels; per-unit albedo uniform in [lo, hi].
cv::Mat Units(int size, int w, int h, int joint, int stagger, float lo, float hi, float mortar,
              std::mt19937& rng) {
  std::uniform_real_distribution<float> albedo(lo, hi);
  cv::Mat tex(size, size, CV_32F, cv::Scalar(mortar));
  for (int row = 0; row * h < size; ++row) {
    const int shift = (row % 2) * stagger;
    for (int col = -1; col * w < size; ++col) {
      const float v = albedo(rng);
      const cv::Rect unit(col * w + shift, row * h, w - joint, h - joint);
      DrawWrapped(size,
                  [&](cv::Point o) { cv::rectangle(tex, unit + o, cv::Scalar(v), cv::FILLED); });
    }
  }
  return tex;
}

cv::Mat Asphalt(std::mt19937& rng) {
  const int size = 1024;
  cv::Mat tex = 0.2f + 0.16f * Fbm(size, 8, 7, 0.6f, rng);
  AddSpeckles(tex, 30000, 2, 0.12f, rng);
  // Repair patches and cracks give the road a few real corners, as on KITTI streets.
  std::uniform_int_distribution<int> pos(0, size - 1), extent(40, 220), step(-12, 12);
  std::uniform_real_distribution<float> shade(-0.08f, 0.05f);
  for (int i = 0; i < 5; ++i) {
    const cv::Rect patch(pos(rng), pos(rng), extent(rng), extent(rng) / 2);
    const float v = shade(rng);
    cv::Mat delta = cv::Mat::zeros(tex.size(), CV_32F);
    DrawWrapped(size, [&](cv::Point o) { cv::rectangle(delta, patch + o, cv::Scalar(v), -1); });
    tex += delta;
  }
  for (int i = 0; i < 4; ++i) {
    cv::Point p(pos(rng), pos(rng));
    for (int k = 0; k < 30; ++k) {
      const cv::Point q = p + cv::Point(12 + step(rng) / 2, step(rng));
      DrawWrapped(size, [&](cv::Point o) { cv::line(tex, p + o, q + o, cv::Scalar(0.08), 2); });
      p = q;
    }
  }
  return tex;
}

cv::Mat Plaster(std::mt19937& rng) {
  const int size = 1024;
  cv::Mat tex = 0.45f + 0.3f * Fbm(size, 4, 8, 0.55f, rng);
  AddSpeckles(tex, 6000, 2, 0.06f, rng);
  // Posters and patches: high-contrast rectangles with text-like rows.
  std::uniform_int_distribution<int> pos(0, size - 1), extent(40, 120);
  std::uniform_real_distribution<float> value(0.05f, 0.95f);
  for (int i = 0; i < 6; ++i) {
    const cv::Rect r(pos(rng), pos(rng), extent(rng), extent(rng));
    const float bg = value(rng);
    DrawWrapped(size, [&](cv::Point o) { cv::rectangle(tex, r + o, cv::Scalar(bg), -1); });
    for (int y = r.y + 6; y + 6 < r.y + r.height; y += 12) {
      for (int x = r.x + 5; x + 8 < r.x + r.width; x += 10) {
        if (value(rng) < 0.35f) continue;
        const cv::Rect glyph(x, y, 7, 7);
        const float fg = bg > 0.5f ? 0.1f : 0.9f;
        DrawWrapped(size, [&](cv::Point o) { cv::rectangle(tex, glyph + o, cv::Scalar(fg), -1); });
      }
    }
  }
  return tex;
}

cv::Mat Panels(std::mt19937& rng) {
  const int size = 1024;
  cv::Mat tex = Units(size, 256, 128, 3, 0, 0.45f, 0.7f, 0.15f, rng);
  tex += 0.12f * (Fbm(size, 8, 7, 0.6f, rng) - 0.5f);
  for (int y = 0; y < size; y += 128) {
    for (int x = 0; x < size; x += 256) {
      for (const cv::Point c :
           {cv::Point(16, 16), cv::Point(237, 16), cv::Point(16, 109), cv::Point(237, 109)}) {
        cv::circle(tex, cv::Point(x, y) + c, 4, cv::Scalar(0.1), -1);
      }
    }
  }
  return tex;
}

cv::Mat Noise(int size, int base_cells, int octaves, std::mt19937& rng) {
  return Fbm(size, base_cells, octaves, 0.55f, rng);
}

std::vector<MipTexture> ProceduralWalls(std::mt19937& rng) {
  std::vector<MipTexture> walls;
  cv::Mat brick = Units(1024, 32, 8, 1, 16, 0.28f, 0.55f, 0.72f, rng);
  brick += 0.08f * (Fbm(1024, 16, 6, 0.6f, rng) - 0.5f);
  walls.emplace_back(brick, 0.01f);
  walls.emplace_back(Plaster(rng), 0.01f);
  walls.emplace_back(Panels(rng), 0.01f);
  cv::Mat stone = Units(1024, 128, 64, 4, 64, 0.35f, 0.65f, 0.2f, rng);
  stone += 0.2f * (Fbm(1024, 16, 7, 0.65f, rng) - 0.5f);
  walls.emplace_back(stone, 0.01f);
  return walls;
}

}  // namespace

MipTexture::MipTexture(const cv::Mat& level0, float texel_size)
    : texel_size_(texel_size), inv_texel_(1.0f / texel_size) {
  CV_Assert(level0.type() == CV_32FC1 && level0.rows == level0.cols);
  CV_Assert((level0.rows & (level0.rows - 1)) == 0);
  cv::Mat current = level0.clone();
  while (true) {
    Level level;
    level.size = current.rows;
    level.texels.assign(current.begin<float>(), current.end<float>());
    levels_.push_back(std::move(level));
    if (current.rows == 1) break;
    cv::Mat half;
    // INTER_AREA halving averages exact 2x2 blocks, which keeps the pyramid tileable.
    cv::resize(current, half, cv::Size(current.cols / 2, current.rows / 2), 0, 0, cv::INTER_AREA);
    current = half;
  }
}

float MipTexture::Bilinear(const Level& level, float x, float y) const {
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int mask = level.size - 1;
  const int x0 = static_cast<int>(fx) & mask, y0 = static_cast<int>(fy) & mask;
  const int x1 = (x0 + 1) & mask, y1 = (y0 + 1) & mask;
  const float* t = level.texels.data();
  const float a = t[y0 * level.size + x0], b = t[y0 * level.size + x1];
  const float c = t[y1 * level.size + x0], d = t[y1 * level.size + x1];
  return (a + (b - a) * tx) * (1.0f - ty) + (c + (d - c) * tx) * ty;
}

float MipTexture::Sample(float u, float v, float footprint) const {
  const float texels = footprint * inv_texel_;
  const float max_lod = static_cast<float>(levels_.size() - 1);
  const float lod = texels > 1.0f ? std::min(std::log2(texels), max_lod) : 0.0f;
  const int l0 = static_cast<int>(lod);
  const float frac = lod - static_cast<float>(l0);
  const float x = u * inv_texel_, y = v * inv_texel_;
  const float s0 = std::ldexp(1.0f, -l0);
  const float a = Bilinear(levels_[l0], x * s0 - 0.5f, y * s0 - 0.5f);
  if (frac < 1e-3f || l0 + 1 >= static_cast<int>(levels_.size())) return a;
  const float s1 = 0.5f * s0;
  const float b = Bilinear(levels_[l0 + 1], x * s1 - 0.5f, y * s1 - 0.5f);
  return a + (b - a) * frac;
}

TextureBank TextureBank::Procedural(std::uint32_t seed) {
  // One generator per texture so adding a texture never changes the others.
  auto rng_for = [seed](std::uint32_t stream) { return std::mt19937(seed * 7919u + stream); };
  TextureBank bank;
  auto rng = rng_for(1);
  bank.asphalt = MipTexture(Asphalt(rng), 0.02f);
  rng = rng_for(2);
  cv::Mat pavers = Units(1024, 64, 32, 2, 32, 0.42f, 0.6f, 0.22f, rng);
  pavers += 0.1f * (Fbm(1024, 8, 7, 0.6f, rng) - 0.5f);
  AddSpeckles(pavers, 3000, 3, 0.08f, rng);
  bank.pavers = MipTexture(pavers, 0.01f);
  rng = rng_for(3);
  bank.concrete = MipTexture(0.5f + 0.2f * (Fbm(512, 8, 6, 0.6f, rng) - 0.5f), 0.01f);
  rng = rng_for(4);
  cv::Mat leaves = Fbm(512, 32, 4, 0.6f, rng);
  leaves = 0.1f + 0.5f * leaves.mul(leaves);
  AddSpeckles(leaves, 20000, 2, 0.15f, rng);
  bank.foliage = MipTexture(leaves, 0.02f);
  rng = rng_for(5);
  cv::Mat streaks = Noise(256, 8, 4, rng), bark;
  cv::resize(streaks(cv::Rect(0, 0, 256, 32)), bark, cv::Size(256, 256), 0, 0, cv::INTER_LINEAR);
  bank.bark = MipTexture(0.15f + 0.3f * bark, 0.01f);
  rng = rng_for(6);
  bank.stains = MipTexture(Noise(512, 4, 6, rng), 0.1f);
  rng = rng_for(7);
  bank.walls = ProceduralWalls(rng);
  return bank;
}

TextureBank TextureBank::WithWallImages(std::uint32_t seed, const std::filesystem::path& dir) {
  std::error_code error;
  std::vector<std::filesystem::path> files;
  std::filesystem::directory_iterator it(dir, error);
  CheckInput(!error, dir.string(), 0, "cannot read the texture folder: " + error.message(),
             "pass an existing, readable folder of png/jpg images to --texture-dir");
  for (; it != std::filesystem::directory_iterator(); it.increment(error)) {
    std::string ext = it->path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp")
      files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  TextureBank bank = Procedural(seed);
  bank.walls.clear();
  for (const auto& file : files) {
    const cv::Mat grey = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    if (grey.empty()) continue;
    // A centred square crop keeps the photo's aspect; rows flip so the photo's bottom is at v = 0
    // (texture v grows upwards on facades).
    const int side = std::min(grey.cols, grey.rows);
    const cv::Mat crop = grey(cv::Rect((grey.cols - side) / 2, (grey.rows - side) / 2, side, side));
    cv::Mat flipped, resized, albedo;
    cv::flip(crop, flipped, 0);
    cv::resize(flipped, resized, cv::Size(1024, 1024), 0, 0,
               side >= 1024 ? cv::INTER_AREA : cv::INTER_LINEAR);
    resized.convertTo(albedo, CV_32F, 1.0 / 255.0);
    bank.walls.emplace_back(albedo, 0.01f);
  }
  CheckInput(!bank.walls.empty(), dir.string(), 0, "no decodable image in the texture folder",
             "put .png/.jpg facade photos in the folder, or omit --texture-dir");
  bank.photo_walls = true;
  return bank;
}

}  // namespace planeloc::sim
