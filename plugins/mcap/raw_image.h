// The JSON messages of a Tilth recording: images as foxglove.RawImage (so Foxglove
// shows them as they are) and the ground truth distance, with their JSON schemas.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <opencv2/core/mat.hpp>

namespace tilth::mcap {

inline constexpr std::string_view kRawImageSchemaName = "foxglove.RawImage";
inline constexpr std::string_view kGroundTruthSchemaName = "tilth.GroundTruth";
inline constexpr std::string_view kJsonSchemaEncoding = "jsonschema";
inline constexpr std::string_view kJsonEncoding = "json";

std::string raw_image_schema();
std::string ground_truth_schema();

// `encoding` as Foxglove names it: "mono16" (little-endian), "mono8", "bgr8", "rgb8",
// "bayer_rggb8", ... The image must be continuous or is copied.
std::string encode_raw_image(const cv::Mat& image, std::string_view encoding,
                             std::int64_t timestamp_ns, std::string_view frame_id);

struct RawImage {
  cv::Mat pixels;  // CV_16UC1 for mono16, CV_8UC3 for bgr8/rgb8, CV_8UC1 otherwise
  std::string encoding;
  std::int64_t timestamp_ns = 0;
};
// Throws tilth::Error naming `where` for a message that is not a RawImage Tilth can
// hold.
RawImage decode_raw_image(std::string_view json, const std::string& where);

std::string encode_ground_truth(std::optional<double> distance_mm, bool has_mask,
                                std::int64_t timestamp_ns);
struct GroundTruthMessage {
  std::optional<double> distance_mm;
  bool has_mask = false;
};
GroundTruthMessage decode_ground_truth(std::string_view json, const std::string& where);

}  // namespace tilth::mcap
