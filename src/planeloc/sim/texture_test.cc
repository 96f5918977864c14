#include "planeloc/sim/texture.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::sim {
namespace {

cv::Mat Checkerboard(int size, int cell) {
  cv::Mat tex(size, size, CV_32F);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) tex.at<float>(y, x) = ((x / cell + y / cell) % 2) ? 0.9f : 0.1f;
  }
  return tex;
}

// Near: the texel itself; far (footprint >> cell): the average, so distant surfaces do not alias.
TEST(TextureTest, FootprintSelectsTheFilterWidth) {
  const MipTexture tex(Checkerboard(256, 4), 0.01f);  // 4 cm cells
  EXPECT_NEAR(tex.Sample(0.005f, 0.005f, 0.001f), 0.1f, 1e-5f);
  EXPECT_NEAR(tex.Sample(0.045f, 0.005f, 0.001f), 0.9f, 1e-5f);
  for (float u : {0.013f, 0.37f, 1.91f}) EXPECT_NEAR(tex.Sample(u, 0.71f, 0.5f), 0.5f, 0.02f);
  // Wraps: one tile is 2.56 m.
  EXPECT_NEAR(tex.Sample(2.56f + 0.045f, 0.005f, 0.001f), 0.9f, 1e-5f);
}

TEST(TextureTest, ProceduralBankIsDeterministicAndTextured) {
  const TextureBank a = TextureBank::Procedural(5), b = TextureBank::Procedural(5);
  ASSERT_EQ(a.walls.size(), 4u);
  double spread = 0.0;
  for (float u = 0.0f; u < 3.0f; u += 0.173f) {
    EXPECT_EQ(a.walls[0].Sample(u, 1.3f, 0.01f), b.walls[0].Sample(u, 1.3f, 0.01f));
    spread += std::abs(a.asphalt.Sample(u, 0.3f, 0.02f) - a.asphalt.Sample(u + 0.05f, 0.3f, 0.02f));
  }
  EXPECT_GT(spread, 0.1);  // the road has texture at the 5 cm scale
}

TEST(TextureTest, WallImagesAreCroppedAndUpright) {
  TempDir dir("planeloc-sim-textures");
  cv::Mat photo(300, 500, CV_8UC1, cv::Scalar(200));
  photo.rowRange(150, 300).setTo(20);  // dark lower half
  ASSERT_TRUE(cv::imwrite((dir.path() / "wall.png").string(), photo));
  std::ofstream(dir.path() / "notes.txt") << "not an image\n";
  const TextureBank bank = TextureBank::WithWallImages(1, dir.path());
  ASSERT_EQ(bank.walls.size(), 1u);
  EXPECT_TRUE(bank.photo_walls);
  // v grows upwards on a facade: the photo's bottom (dark) is at v ~ 0.
  EXPECT_NEAR(bank.walls[0].Sample(5.0f, 1.0f, 0.01f), 20.0f / 255.0f, 0.02f);
  EXPECT_NEAR(bank.walls[0].Sample(5.0f, 9.0f, 0.01f), 200.0f / 255.0f, 0.02f);
  TempDir empty("planeloc-sim-textures-empty");
  EXPECT_THROW(TextureBank::WithWallImages(1, empty.path()), InputError);
  EXPECT_THROW(TextureBank::WithWallImages(1, empty.path() / "missing"), InputError);
}

}  // namespace
}  // namespace planeloc::sim
