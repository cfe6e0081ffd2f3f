// An image-folder recording replayed through the measurement chain's own depth projection
// and registration, in process, each frame handed to the caller: the depth and the colour
// on the depth grid exactly as the chain would see them with the calibration checked.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>

#include <opencv2/core/mat.hpp>

namespace tilth::calibrate {

struct RegisteredFrame {
  std::uint64_t frame_id = 0;
  cv::Mat depth_mm;  // CV_32FC1, NaN = no depth
  cv::Mat bgr;       // CV_8UC3 on the depth grid
  cv::Mat status;    // CV_8UC1, RegisteredColor::Status
};

struct ReplayOptions {
  // A calibration file replacing the recording's own (depth projection and registration
  // both); none = the recording's.
  std::optional<std::filesystem::path> calibration;
  std::optional<std::uint64_t> max_frames;
};

// Runs recording.image_folder -> depth.projection -> registration.projective and calls
// `on_frame` for each frame, in order, on a runtime thread. Occlusion is not flagged: a
// pixel keeps the colour the camera saw there, so colour edges stay where the colour
// camera put them rather than where the depth says an occluded band begins. Throws
// tilth::Error when a stage cannot start (no recording, a malformed calibration) or a
// frame fails (a calibration for other image sizes), naming the node and the file, and
// when a stop signal ends the replay early.
void replay_registered(const std::filesystem::path& recording, const ReplayOptions& options,
                       const std::function<void(const RegisteredFrame&)>& on_frame);

}  // namespace tilth::calibrate
