// What a Tilth MCAP recording holds (docs/formats/mcap-recording.md): its channels, the
// calibration attachment and metadata, so the writer, the player and the tools agree on
// the names.
#pragma once

#include <string_view>

namespace tilth::mcap {

inline constexpr std::string_view kRawTopic = "/tof/raw";        // RawImage mono16
inline constexpr std::string_view kColorTopic = "/color/image";  // bgr8, rgb8 or bayer_*8
inline constexpr std::string_view kTruthTopic = "/truth";        // tilth.GroundTruth
inline constexpr std::string_view kMaskTopic = "/truth/mask";    // RawImage mono8

inline constexpr std::string_view kCalibrationAttachment = "rig.calib.json";
inline constexpr std::string_view kCalibrationMetadata = "tilth.calibration";  // key "json"
inline constexpr std::string_view kRecordingMetadata = "tilth.recording";
inline constexpr std::string_view kTofFrameId = "tof";
inline constexpr std::string_view kColorFrameId = "color";

}  // namespace tilth::mcap
