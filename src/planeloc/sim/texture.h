// Grey textures for the simulator: tileable procedural albedo maps (asphalt, paving slabs, brick,
// plaster, concrete panels, stone, foliage, bark, large-scale stains) with box-filtered mip
// pyramids, sampled trilinearly by the pixel footprint so distant surfaces do not alias.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

namespace planeloc::sim {

// A square, power-of-two, wrapping texture; texel values are albedo in [0, 1].
class MipTexture {
 public:
  MipTexture() = default;
  // `level0` is CV_32FC1, square, power-of-two sized; `texel_size` in metres.
  MipTexture(const cv::Mat& level0, float texel_size);

  // Albedo at surface coordinates (u, v) in metres, averaged over a footprint of `footprint`
  // metres (trilinear: bilinear in the two mip levels around log2(footprint / texel)).
  float Sample(float u, float v, float footprint) const;
  int size() const { return levels_.empty() ? 0 : levels_[0].size; }
  float texel_size() const { return texel_size_; }

 private:
  struct Level {
    int size = 0;
    std::vector<float> texels;
  };
  float Bilinear(const Level& level, float x, float y) const;

  std::vector<Level> levels_;
  float texel_size_ = 0.01f;
  float inv_texel_ = 100.0f;
};

struct TextureBank {
  MipTexture asphalt;             // 2 cm texels
  MipTexture pavers;              // 1 cm
  MipTexture concrete;            // curbs, 1 cm
  MipTexture foliage;             // 2 cm
  MipTexture bark;                // 1 cm
  MipTexture stains;              // 10 cm, low-frequency dirt modulating facades
  std::vector<MipTexture> walls;  // facade wall materials
  bool photo_walls = false;       // walls come from --texture-dir (no procedural windows)

  // Fully determined by `seed` (independent of the thread count).
  static TextureBank Procedural(std::uint32_t seed);
  // Procedural bank whose walls are the images (png/jpg/jpeg/bmp, sorted by name) of `dir`,
  // centre-cropped to a square, converted to grey and resampled to 1024x1024 texels of 1 cm. Throws
  // InputError if the folder cannot be read or holds no decodable image.
  static TextureBank WithWallImages(std::uint32_t seed, const std::filesystem::path& dir);
};

}  // namespace planeloc::sim
