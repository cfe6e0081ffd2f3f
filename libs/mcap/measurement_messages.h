// What the chain measured and the rig it measured with, as JSON messages Foxglove reads:
// the distance handed to the machine (tilth.GroundDistance, so it plots), the cameras'
// health (tilth.CameraStatus), and each camera's intrinsics and the pose of the colour
// camera (foxglove.CameraCalibration, foxglove.FrameTransform).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "tilth/calibration.h"
#include "tilth/messages/camera_status.h"
#include "tilth/messages/ground_distance.h"

namespace tilth::mcap {

inline constexpr std::string_view kGroundDistanceSchemaName = "tilth.GroundDistance";
inline constexpr std::string_view kCameraStatusSchemaName = "tilth.CameraStatus";
inline constexpr std::string_view kCameraCalibrationSchemaName = "foxglove.CameraCalibration";
inline constexpr std::string_view kFrameTransformSchemaName = "foxglove.FrameTransform";

// JSON Schemas (schema encoding "jsonschema") of the messages below.
std::string ground_distance_schema();
std::string camera_status_schema();
std::string camera_calibration_schema();
std::string frame_transform_schema();

// `timestamp_ns`: the frame's depth device time, as its images'.
std::string encode_ground_distance(const GroundDistance& distance, std::int64_t timestamp_ns);
// Throws tilth::Error naming `where` for a message that is not a tilth.GroundDistance.
GroundDistance decode_ground_distance(std::string_view json, const std::string& where);
std::string encode_camera_status(const CameraStatus& status, std::int64_t timestamp_ns);
// A pinhole camera with OpenCV's k1, k2, p1, p2, k3 ("plumb_bob"), unrectified.
std::string encode_camera_calibration(const CameraIntrinsics& camera, std::string_view frame_id,
                                      std::int64_t timestamp_ns);
// The colour camera's frame in the depth camera's (parent): the inverse of the
// calibration's depth_to_color (P_c = R P_d + T), in metres.
std::string encode_color_pose(const RigCalibration& rig, std::string_view depth_frame_id,
                              std::string_view color_frame_id, std::int64_t timestamp_ns);

}  // namespace tilth::mcap
