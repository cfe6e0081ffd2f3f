// Images in a Tilth recording: Foxglove's RawImage in its ROS 2 form
// (foxglove_msgs/msg/RawImage, CDR-encoded), which Foxglove shows as it is. The pixels
// are stored as they are, so writing or reading an image is one copy of its rows.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <opencv2/core/mat.hpp>

namespace tilth::mcap {

inline constexpr std::string_view kRawImageSchemaName = "foxglove_msgs/msg/RawImage";
inline constexpr std::string_view kRos2MsgSchemaEncoding = "ros2msg";
inline constexpr std::string_view kCdrEncoding = "cdr";

// The ros2msg definition of the schema, with builtin_interfaces/Time.
std::string raw_image_schema();

// `encoding` as Foxglove names it: "mono16" (little-endian), "mono8", "bgr8", "rgb8",
// "bayer_rggb8", ... The image must be continuous or is copied.
std::string encode_raw_image(const cv::Mat& image, std::string_view encoding,
                             std::int64_t timestamp_ns, std::string_view frame_id);

struct RawImage {
  cv::Mat pixels;  // CV_16UC1 for mono16, CV_8UC3 for bgr8/rgb8, CV_8UC1 otherwise
  std::string encoding;
  std::string frame_id;
  std::int64_t timestamp_ns = 0;
};
// Throws tilth::Error naming `where` and the field for a message that is not a RawImage
// Tilth can hold.
RawImage decode_raw_image(std::string_view cdr, const std::string& where);

}  // namespace tilth::mcap
