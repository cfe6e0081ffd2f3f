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
// What the chain measured, when the graph gives it to the writer.
inline constexpr std::string_view kDistanceTopic = "/tilth/distance";  // tilth.GroundDistance
inline constexpr std::string_view kResidueMaskTopic = "/tilth/mask";   // RawImage mono8
inline constexpr std::string_view kRegisteredColorTopic = "/tilth/registered_color";  // bgr8
inline constexpr std::string_view kCameraStatusTopic = "/tilth/cameras";  // tilth.CameraStatus
// The rig, once, with the first frame.
inline constexpr std::string_view kTofCalibrationTopic = "/tof/calibration";
inline constexpr std::string_view kColorCalibrationTopic = "/color/calibration";
inline constexpr std::string_view kTransformTopic = "/tf";  // foxglove.FrameTransform

inline constexpr std::string_view kCalibrationAttachment = "rig.calib.json";
inline constexpr std::string_view kCalibrationMetadata = "tilth.calibration";  // key "json"
inline constexpr std::string_view kRecordingMetadata = "tilth.recording";
inline constexpr std::string_view kTofFrameId = "tof";
inline constexpr std::string_view kColorFrameId = "color";

}  // namespace tilth::mcap
