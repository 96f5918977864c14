#include "planeloc/io/grey_image.h"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>
#include <system_error>

#include "planeloc/util/error.h"

namespace planeloc {

cv::Mat LoadGreyImage(const std::filesystem::path& path) {
  std::error_code error;
  CheckInput(std::filesystem::is_regular_file(path, error), path.string(), 0, "image file missing",
             "re-extract the sequence, or skip frames for which HasFrame() is false");
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  CheckInput(!image.empty(), path.string(), 0, "image does not decode",
             "the file is corrupt or not an image; re-extract it from the dataset's archive");
  double lowest = 0.0, highest = 0.0;
  cv::minMaxLoc(image, &lowest, &highest);
  CheckInput(lowest < highest, path.string(), 0,
             fmt::format("the image is blank (every pixel is {})", lowest),
             "the camera saw nothing (covered lens, blackout, zero-filled file); restore the image "
             "or drop the frame");
  return image;
}

}  // namespace planeloc
