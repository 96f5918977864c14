#include "planeloc/ros/bag_writer.h"

#include <cv_bridge/cv_bridge.h>
#include <fmt/format.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "planeloc/ros/bag_sequence.h"
#include "planeloc/ros/ros_conversions.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::ros {
namespace {

bool Compressed(const std::string& encoding) { return encoding == "png" || encoding == "jpeg"; }

// Writes one image message (raw or compressed) of the grey `image`.
void WriteImage(rosbag::Bag& bag, const std::string& topic, const std::string& encoding,
                const std_msgs::Header& header, const cv::Mat& grey) {
  namespace enc = sensor_msgs::image_encodings;
  if (Compressed(encoding)) {
    cv_bridge::CvImage image(header, enc::MONO8, grey);
    bag.write(topic, header.stamp,
              *image.toCompressedImageMsg(encoding == "png" ? cv_bridge::PNG : cv_bridge::JPG));
    return;
  }
  cv::Mat converted = grey;
  if (encoding == enc::RGB8) cv::cvtColor(grey, converted, cv::COLOR_GRAY2RGB);
  if (encoding == enc::BGR8) cv::cvtColor(grey, converted, cv::COLOR_GRAY2BGR);
  bag.write(topic, header.stamp, *cv_bridge::CvImage(header, encoding, converted).toImageMsg());
}

}  // namespace

void BagWriteOptions::Check() const {
  if (left_topic.empty() || right_topic.empty() || left_topic == right_topic) {
    throw OptionsError("BagWriteOptions.left_topic/right_topic: two different, non-empty topics");
  }
  if (!IsSupportedEncoding(encoding) && !Compressed(encoding)) {
    throw OptionsError("BagWriteOptions.encoding: mono8, rgb8, bgr8, png or jpeg");
  }
  if (!(start_time > 0) || !std::isfinite(start_time)) {
    throw OptionsError("BagWriteOptions.start_time: must be finite and > 0 (seconds)");
  }
  if (max_frames < 0) throw OptionsError("BagWriteOptions.max_frames: must be >= 0");
}

int WriteStereoBag(const StereoSource& source, const std::filesystem::path& bag_path,
                   const BagWriteOptions& options) {
  options.Check();
  const int frames = options.max_frames > 0
                         ? std::min<int>(options.max_frames, static_cast<int>(source.size()))
                         : static_cast<int>(source.size());
  const std::filesystem::path temporary = TemporaryPathFor(bag_path);
  sensor_msgs::CameraInfo left_info = CameraInfoFromStereo(source.camera(), false);
  sensor_msgs::CameraInfo right_info = CameraInfoFromStereo(source.camera(), true);
  left_info.header.frame_id = right_info.header.frame_id = options.frame_id;
  const std::string left_info_topic = CameraInfoTopicFor(options.left_topic);
  const std::string right_info_topic = CameraInfoTopicFor(options.right_topic);
  {
    rosbag::Bag bag;
    try {
      bag.open(temporary.string(), rosbag::bagmode::Write);
    } catch (const rosbag::BagException& e) {
      throw InputError(bag_path.string(), 0, fmt::format("cannot write the bag: {}", e.what()),
                       "check that the folder exists and is writable");
    }
    try {
      for (int i = 0; i < frames; ++i) {
        const StereoPair pair = source.LoadStereoPair(i);
        std_msgs::Header header;
        header.seq = i;
        header.frame_id = options.frame_id;
        header.stamp = ::ros::Time(options.start_time + source.timestamp(i));
        left_info.header = right_info.header = header;
        WriteImage(bag, options.left_topic, options.encoding, header, pair.left);
        WriteImage(bag, options.right_topic, options.encoding, header, pair.right);
        bag.write(left_info_topic, header.stamp, left_info);
        bag.write(right_info_topic, header.stamp, right_info);
      }
      bag.close();
    } catch (...) {
      bag.close();
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);  // no half-written bag left behind
      throw;
    }
  }
  CommitTemporary(temporary, bag_path);
  return frames;
}

}  // namespace planeloc::ros
