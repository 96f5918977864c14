// Reading one camera image as 8-bit grey, with the checks every image source applies.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

namespace planeloc {

// Decodes `path` as CV_8UC1 (colour images are converted). Throws InputError naming the file
// when it is missing, does not decode, or is blank (one grey value: a covered lens, a blackout,
// a zero-filled file, which tracked as is gives a pose from nothing).
cv::Mat LoadGreyImage(const std::filesystem::path& path);

}  // namespace planeloc
