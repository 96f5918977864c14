#include "planeloc/sim/shading.h"

#include <algorithm>
#include <cmath>

namespace planeloc::sim {
namespace {

// Fraction of the footprint [x - fp/2, x + fp/2] inside [lo, hi]: an analytically box-filtered
// step, the reason windows and glyphs do not alias at any distance.
float Coverage(float x, float lo, float hi, float fp) {
  const float h = 0.5f * std::max(fp, 1e-4f);
  return std::clamp((std::min(x + h, hi) - std::max(x - h, lo)) / (2.0f * h), 0.0f, 1.0f);
}

float RectCoverage(float u, float v, float u0, float u1, float v0, float v1, float fp) {
  return Coverage(u, u0, u1, fp) * Coverage(v, v0, v1, fp);
}

float Mix(float a, float b, float t) { return a + (b - a) * t; }

float Unit(std::uint32_t h) { return static_cast<float>(h & 0xffffff) / 16777216.0f; }

}  // namespace

std::uint32_t HashCombine(std::uint32_t a, std::uint32_t b) {
  std::uint32_t h = a * 0x9e3779b1u ^ (b + 0x7f4a7c15u + (a << 6) + (a >> 2));
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return h;
}

std::uint32_t HashCombine(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  return HashCombine(HashCombine(a, b), c);
}

Shader::Shader(const World& world, const TextureBank& bank) : world_(world), bank_(bank) {
  for (const auto& q : world.quads) {
    quad_sizes_.emplace_back(static_cast<float>(q.edge_u.norm()),
                             static_cast<float>(q.edge_v.norm()));
  }
}

float Shader::Windows(const FacadeStyle& s, float u, float v, float width, float height, float wall,
                      float fp) const {
  const float fh = static_cast<float>(s.floor_height),
              spacing = static_cast<float>(s.window_spacing);
  const float ww = static_cast<float>(s.window_width), wh = static_cast<float>(s.window_height);
  const int storey = static_cast<int>(std::floor(v / fh));
  const float vin = v - storey * fh;
  const float sill = storey == 0 ? 1.1f : static_cast<float>(s.sill_height);
  if ((storey + 1) * fh > height - 0.4f) return wall;  // no windows in the attic band
  const int columns = std::max(1, static_cast<int>((width - 1.0f) / spacing));
  const float start = 0.5f * (width - columns * spacing);
  const int col = static_cast<int>(std::floor((u - start) / spacing));
  if (col < 0 || col >= columns) return wall;
  const float x = u - (start + (col + 0.5f) * spacing);
  const float hw = 0.5f * ww;
  const float window = RectCoverage(x, vin, -hw, hw, sill, sill + wh, fp);
  const float ledge = RectCoverage(x, vin, -hw - 0.08f, hw + 0.08f, sill - 0.1f, sill, fp);
  if (window <= 0.0f && ledge <= 0.0f) return wall;
  const std::uint32_t h =
      HashCombine(s.hash, static_cast<std::uint32_t>(col), static_cast<std::uint32_t>(storey));
  float glass = 0.05f + 0.3f * Unit(h) + 0.08f * (vin - sill) / wh;
  if ((h >> 24) % 4 == 0) {  // curtains: folds fade out once they are smaller than the footprint
    const float folds = std::sin(x * 25.0f) * std::clamp(0.06f / fp - 0.5f, 0.0f, 1.0f);
    glass = 0.55f + 0.15f * folds;
  }
  const float frame_value = (s.hash & 1u) ? 0.85f : 0.12f;
  const float inner =
      RectCoverage(x, vin, -hw + 0.07f, hw - 0.07f, sill + 0.07f, sill + wh - 0.07f, fp);
  const float mullion = Coverage(x, -0.03f, 0.03f, fp);
  const float transom = Coverage(vin, sill + 0.65f * wh - 0.03f, sill + 0.65f * wh + 0.03f, fp);
  const float pane = inner * (1.0f - mullion) * (1.0f - transom);
  float value = Mix(wall, Mix(frame_value, glass, pane), window);
  value = Mix(value, 0.8f, ledge * (1.0f - window));
  return value;
}

float Shader::ShopFront(const FacadeStyle& s, float u, float v, float width, float wall,
                        float fp) const {
  // Sign band with block letters: strong corners at street level, as shop fronts give in KITTI.
  const float band_lo = 2.3f, band_hi = 2.85f;
  const float band = RectCoverage(u, v, 0.3f, width - 0.3f, band_lo, band_hi, fp);
  float value = wall;
  if (band > 0.0f) {
    const float bg = 0.1f + 0.8f * Unit(HashCombine(s.hash, 99u));
    const float fg = bg > 0.5f ? 0.08f : 0.92f;
    const float cell = 0.36f;
    const int letter = static_cast<int>(std::floor((u - 0.6f) / cell));
    const float lx = u - 0.6f - letter * cell, ly = v - band_lo - 0.1f;
    float glyph = 0.0f;
    if (letter >= 0 && u < width - 0.6f && lx < 0.24f && ly >= 0.0f && ly < 0.35f) {
      const int gx = static_cast<int>(lx / 0.08f), gy = static_cast<int>(ly / 0.07f);
      const std::uint32_t bits = HashCombine(s.hash, static_cast<std::uint32_t>(letter));
      glyph = ((bits >> (gy * 3 + gx)) & 1u) ? 1.0f : 0.0f;
    }
    // Glyph cells are 7 cm: fade them to their mean when the footprint approaches that size.
    const float detail = std::clamp(1.5f - fp / 0.04f, 0.0f, 1.0f);
    glyph = Mix(0.3f, glyph, detail);
    value = Mix(wall, Mix(bg, fg, glyph), band);
  }
  const float bay_width = 3.6f;
  const int bay = static_cast<int>(std::floor(u / bay_width));
  const float bx = u - bay * bay_width;
  const float glass = RectCoverage(bx, v, 0.35f, bay_width - 0.05f, 0.45f, 2.1f, fp) *
                      Coverage(u, 0.3f, width - 0.3f, fp);
  if (glass > 0.0f) {
    const std::uint32_t h = HashCombine(s.hash, static_cast<std::uint32_t>(bay), 7u);
    const bool door = h % 5 == 0;
    float pane = door ? 0.06f : 0.1f + 0.2f * Unit(h);
    if (!door) {  // display shelves
      const float shelf = Coverage(v, 0.95f, 1.0f, fp) + Coverage(v, 1.5f, 1.55f, fp);
      pane = Mix(pane, 0.7f, std::min(shelf, 1.0f));
    }
    value = Mix(value, pane, glass);
  }
  return value;
}

float Shader::Facade(const FacadeStyle& s, float u, float v, float width, float height,
                     float fp) const {
  const auto& walls = bank_.walls;
  const MipTexture& tex = walls[static_cast<std::size_t>(s.wall_texture) % walls.size()];
  const float off = static_cast<float>(s.hash % 997u) * 0.37f;
  float wall =
      tex.Sample(u + off, v + 0.5f * off, fp) * static_cast<float>(s.wall_brightness) * 2.0f;
  wall *= 0.7f + 0.6f * bank_.stains.Sample(u + 3.0f * off, v, fp);
  if (bank_.photo_walls) return std::clamp(wall, 0.0f, 1.0f);
  // Cornice: a dark band under the roof line.
  wall = Mix(wall, 0.2f, Coverage(v, height - 0.45f, height - 0.2f, fp));
  float value = wall;
  if (s.shop_front && v < s.floor_height) {
    value = ShopFront(s, u, v, width, wall, fp);
  } else {
    value = Windows(s, u, v, width, height, wall, fp);
  }
  return std::clamp(value, 0.0f, 1.0f);
}

float Shader::Interior(int style, float u, float v, float width, float height, float fp) const {
  const auto& walls = bank_.walls;
  const std::uint32_t seed = HashCombine(static_cast<std::uint32_t>(style), 0x5eedu);
  const MipTexture& tex = walls[seed % walls.size()];
  const float off = static_cast<float>(seed % 997u) * 0.37f;
  const float wall =
      std::clamp(tex.Sample(u + off, v + 0.5f * off, fp) * (0.9f + 0.5f * Unit(seed >> 8)) *
                     (0.8f + 0.4f * bank_.stains.Sample(u + 3.0f * off, v, fp)),
                 0.0f, 1.0f);
  // Posters and marker boards on a 1.6 x 1.4 m grid, as the calibration boards and posters of the
  // EuRoC Vicon rooms: the corners ORB finds on otherwise plain walls and furniture.
  const float cell_u = 1.6f, cell_v = 1.4f;
  const int cu = static_cast<int>(std::floor(u / cell_u)),
            cv = static_cast<int>(std::floor(v / cell_v));
  const std::uint32_t h =
      HashCombine(seed, static_cast<std::uint32_t>(cu), static_cast<std::uint32_t>(cv));
  if (Unit(h) > 0.65f) return wall;
  const float pw = 0.45f + 0.6f * Unit(h >> 3), ph = 0.5f + 0.5f * Unit(h >> 7);
  const float u0 = cu * cell_u + 0.1f + (cell_u - 0.2f - pw) * Unit(h >> 11);
  const float v0 = cv * cell_v + 0.1f + (cell_v - 0.2f - ph) * Unit(h >> 15);
  const float inside = RectCoverage(u, v, u0, u0 + pw, v0, v0 + ph, fp);
  if (inside <= 0.0f || u0 + pw > width || v0 + ph > height) return wall;
  // A 6 x 6 grid of black and white cells inside a white margin (an ArUco-like board); cells
  // fade to their mean once the footprint nears their size, so distant boards do not alias.
  const float margin = 0.06f;
  const float gx = (u - u0 - margin) / (pw - 2.0f * margin) * 6.0f;
  const float gy = (v - v0 - margin) / (ph - 2.0f * margin) * 6.0f;
  float board = 0.92f;
  if (gx >= 0.0f && gx < 6.0f && gy >= 0.0f && gy < 6.0f) {
    const std::uint32_t bits = HashCombine(h, 0xb0a4du);
    const int ix = static_cast<int>(gx), iy = static_cast<int>(gy);
    const bool black = ix == 0 || iy == 0 || ix == 5 || iy == 5 || ((bits >> (iy * 4 + ix)) & 1u);
    const float cell = std::min(pw, ph) / 6.0f;
    const float detail = std::clamp(1.5f - fp / (0.5f * cell), 0.0f, 1.0f);
    board = Mix(0.5f, black ? 0.06f : 0.92f, detail);
  }
  return Mix(wall, board, inside);
}

float Shader::Albedo(const Hit& hit, const Eigen::Vector3f& p, float fp) const {
  switch (hit.kind) {
    case PrimitiveKind::kSphere:
      return bank_.foliage.Sample(hit.uv.x(), hit.uv.y(), fp);
    case PrimitiveKind::kCylinder: {
      const Cylinder& c = world_.cylinders[hit.index];
      if (c.material == Material::kBark) return bank_.bark.Sample(hit.uv.x(), hit.uv.y(), fp);
      return 0.45f + 0.1f * bank_.concrete.Sample(hit.uv.x(), hit.uv.y(), fp);
    }
    case PrimitiveKind::kQuad:
      break;
  }
  const Quad& q = world_.quads[hit.index];
  const float u = hit.uv.x() + static_cast<float>(q.uv_offset.x());
  const float v = hit.uv.y() + static_cast<float>(q.uv_offset.y());
  const Eigen::Vector2f size = quad_sizes_[hit.index];
  switch (q.material) {
    case Material::kAsphalt:
      return bank_.asphalt.Sample(p.x(), p.y(), fp);
    case Material::kSidewalk:
      return bank_.pavers.Sample(p.x(), p.y(), fp);
    case Material::kCurb:
      return bank_.concrete.Sample(u, v, fp) * 1.2f;
    case Material::kPaint:
      return 0.75f + 0.5f * (bank_.asphalt.Sample(p.x(), p.y(), fp) - 0.28f);
    case Material::kFacade:
      return Facade(world_.facade_styles[static_cast<std::size_t>(q.style)], hit.uv.x(), hit.uv.y(),
                    size.x(), size.y(), fp);
    case Material::kCarPaint:
      return (0.1f + 0.7f * Unit(HashCombine(static_cast<std::uint32_t>(q.style), 5u))) *
             (0.9f + 0.2f * bank_.concrete.Sample(u, v, fp));
    case Material::kCarGlass:
      return 0.06f + 0.1f * v / std::max(size.y(), 0.1f);
    case Material::kSign: {
      const float border =
          1.0f - RectCoverage(u, v, 0.05f, size.x() - 0.05f, 0.05f, size.y() - 0.05f, fp);
      const float symbol = RectCoverage(u, v, 0.35f * size.x(), 0.55f * size.x(), 0.2f * size.y(),
                                        0.8f * size.y(), fp);
      return Mix(0.9f, 0.1f, std::min(1.0f, border + symbol));
    }
    case Material::kMarker: {
      const float black = RectCoverage(u, v, 0.25f * size.x(), 0.75f * size.x(), 0.25f * size.y(),
                                       0.75f * size.y(), fp);
      return Mix(0.95f, 0.05f, black);
    }
    case Material::kFoliage:
      return bank_.foliage.Sample(u, v, fp);
    case Material::kBark:
      return bank_.bark.Sample(u, v, fp);
    case Material::kMetal:
      return 0.5f;
    case Material::kInterior:
      return Interior(q.style, u, v, size.x(), size.y(), fp);
  }
  return 0.5f;
}

float Shader::Reflectance(const Hit& hit, const Eigen::Vector3f& point,
                          const Eigen::Vector3f& dir) const {
  const float albedo = Albedo(hit, point, 0.05f);
  float base = 0.1f + 0.5f * albedo;
  Material material = Material::kFoliage;
  if (hit.kind == PrimitiveKind::kQuad) material = world_.quads[hit.index].material;
  if (hit.kind == PrimitiveKind::kCylinder) material = world_.cylinders[hit.index].material;
  switch (material) {
    case Material::kPaint:
      base = 0.8f;
      break;
    case Material::kSign:
      base = 0.95f;
      break;
    case Material::kCarGlass:
      base = 0.05f;
      break;
    case Material::kFoliage:
      base = 0.35f + 0.3f * albedo;
      break;
    default:
      break;
  }
  const float cosine = std::abs(hit.normal.dot(dir));
  return std::clamp(base * (0.4f + 0.6f * cosine), 0.0f, 1.0f);
}

}  // namespace planeloc::sim
