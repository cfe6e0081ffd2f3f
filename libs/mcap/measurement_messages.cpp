#include "mcap/measurement_messages.h"

#include <array>
#include <cmath>

#include <nlohmann/json.hpp>

#include "mcap/json_time.h"
#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth::mcap {
namespace {

using nlohmann::json;

constexpr double kMetresPerMm = 1e-3;

json numbers(std::size_t count) {
  return {
      {"type", "array"}, {"items", {{"type", "number"}}}, {"minItems", count}, {"maxItems", count}};
}

json object_schema(std::string_view title, std::string_view description, json properties) {
  return {{"title", title},
          {"description", description},
          {"type", "object"},
          {"properties", std::move(properties)}};
}

json optional_number(const std::optional<double>& value) {
  return value ? json(*value) : json(nullptr);
}

// The unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method: from its
// largest diagonal term, so that no division is by a small number), normalised: a
// calibration file's rotation, written to a few decimals, is orthonormal only nearly.
std::array<double, 4> quaternion(const cv::Matx33d& r) {
  const double trace = r(0, 0) + r(1, 1) + r(2, 2);
  std::array<double, 4> q{};
  if (trace > 0) {
    const double s = 2.0 * std::sqrt(1.0 + trace);
    q = {(r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s, s / 4};
  } else if (r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(0, 0) - r(1, 1) - r(2, 2));
    q = {s / 4, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s, (r(2, 1) - r(1, 2)) / s};
  } else if (r(1, 1) > r(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + r(1, 1) - r(0, 0) - r(2, 2));
    q = {(r(0, 1) + r(1, 0)) / s, s / 4, (r(1, 2) + r(2, 1)) / s, (r(0, 2) - r(2, 0)) / s};
  } else {
    const double s = 2.0 * std::sqrt(1.0 + r(2, 2) - r(0, 0) - r(1, 1));
    q = {(r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, s / 4, (r(1, 0) - r(0, 1)) / s};
  }
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& component : q) component /= norm;
  return q;
}

}  // namespace

std::string ground_distance_schema() {
  return object_schema(
             kGroundDistanceSchemaName,
             "The distance the chain measured and handed to the machine: mounting surface to "
             "soil along the optical axis (null when invalid), why not valid, and how far to "
             "trust it",
             {{"timestamp", time_schema()},
              {"frame_id", {{"type", "string"}}},
              {"distance_mm", {{"type", {"number", "null"}}}},
              {"valid", {{"type", "boolean"}}},
              {"invalid_cause", {{"type", "string"}}},
              {"invalid_reason", {{"type", "string"}}},
              {"soil_fraction", {{"type", "number"}}},
              {"soil_pixels", {{"type", "integer"}}},
              {"spread_mm", {{"type", "number"}}},
              {"confidence", {{"type", "number"}}},
              {"tilt_x_deg", {{"type", {"number", "null"}}}},
              {"tilt_y_deg", {{"type", {"number", "null"}}}},
              {"held", {{"type", "boolean"}}},
              {"held_ms", {{"type", "number"}}}})
      .dump();
}

std::string camera_status_schema() {
  return object_schema(kCameraStatusSchemaName,
                       "The cameras' health: whether they stream, why not, their frame counters",
                       {{"timestamp", time_schema()},
                        {"camera", {{"type", "string"}}},
                        {"streaming", {{"type", "boolean"}}},
                        {"problem", {{"type", "string"}}},
                        {"completed", {{"type", "integer"}}},
                        {"incomplete", {{"type", "integer"}}},
                        {"lost", {{"type", "integer"}}},
                        {"late", {{"type", "integer"}}}})
      .dump();
}

std::string camera_calibration_schema() {
  return object_schema(kCameraCalibrationSchemaName, "Camera calibration parameters",
                       {{"timestamp", time_schema()},
                        {"frame_id", {{"type", "string"}}},
                        {"width", {{"type", "integer"}, {"minimum", 0}}},
                        {"height", {{"type", "integer"}, {"minimum", 0}}},
                        {"distortion_model", {{"type", "string"}}},
                        {"D", {{"type", "array"}, {"items", {{"type", "number"}}}}},
                        {"K", numbers(9)},
                        {"R", numbers(9)},
                        {"P", numbers(12)}})
      .dump();
}

std::string frame_transform_schema() {
  const json vector3 = {
      {"type", "object"},
      {"properties",
       {{"x", {{"type", "number"}}}, {"y", {{"type", "number"}}}, {"z", {{"type", "number"}}}}}};
  json quaternion_schema = vector3;
  quaternion_schema["properties"]["w"] = {{"type", "number"}};
  return object_schema(kFrameTransformSchemaName,
                       "A transform between two reference frames in 3D space",
                       {{"timestamp", time_schema()},
                        {"parent_frame_id", {{"type", "string"}}},
                        {"child_frame_id", {{"type", "string"}}},
                        {"translation", vector3},
                        {"rotation", quaternion_schema}})
      .dump();
}

std::string encode_ground_distance(const GroundDistance& distance, std::int64_t timestamp_ns) {
  return json{{"timestamp", time_json(timestamp_ns)},
              {"frame_id", "tof"},
              {"distance_mm", distance.valid ? json(distance.distance_mm) : json(nullptr)},
              {"valid", distance.valid},
              {"invalid_cause", std::string(to_string(distance.cause))},
              {"invalid_reason", distance.invalid_reason},
              {"soil_fraction", distance.soil_fraction},
              {"soil_pixels", distance.soil_pixels},
              {"spread_mm", distance.spread_mm},
              {"confidence", distance.confidence},
              {"tilt_x_deg", optional_number(distance.tilt_x_deg)},
              {"tilt_y_deg", optional_number(distance.tilt_y_deg)},
              {"held", distance.held},
              {"held_ms", distance.held_ms}}
      .dump();
}

GroundDistance decode_ground_distance(std::string_view text, const std::string& where) {
  const json message = parse_json(text, where);
  if (!message.is_object()) throw Error(where + ": message data is not a JSON object");
  try {
    GroundDistance distance;
    const std::string cause = message.at("invalid_cause").get<std::string>();
    for (auto code = static_cast<std::uint8_t>(InvalidCause::kNone);
         code <= static_cast<std::uint8_t>(InvalidCause::kImageUnusable); ++code) {
      if (to_string(static_cast<InvalidCause>(code)) == cause) {
        distance.cause = static_cast<InvalidCause>(code);
      }
    }
    if (to_string(distance.cause) != cause) {
      throw Error(where + ": unknown invalid_cause '" + cause + "'");
    }
    distance.valid = message.at("valid").get<bool>();
    const json& value = message.at("distance_mm");
    if (distance.valid) distance.distance_mm = value.get<double>();
    distance.invalid_reason = message.at("invalid_reason").get<std::string>();
    distance.soil_fraction = message.at("soil_fraction").get<double>();
    distance.soil_pixels = message.at("soil_pixels").get<std::int64_t>();
    distance.spread_mm = message.at("spread_mm").get<double>();
    distance.confidence = message.at("confidence").get<double>();
    for (const auto& [key, tilt] : {std::pair{"tilt_x_deg", &distance.tilt_x_deg},
                                    std::pair{"tilt_y_deg", &distance.tilt_y_deg}}) {
      if (!message.at(key).is_null()) *tilt = message.at(key).get<double>();
    }
    distance.held = message.at("held").get<bool>();
    distance.held_ms = message.at("held_ms").get<double>();
    return distance;
  } catch (const json::exception& error) {
    throw Error(where + ": not a tilth.GroundDistance: " + error.what());
  }
}

std::string encode_camera_status(const CameraStatus& status, std::int64_t timestamp_ns) {
  return json{{"timestamp", time_json(timestamp_ns)},
              {"camera", status.camera},
              {"streaming", status.streaming},
              {"problem", status.problem},
              {"completed", status.completed},
              {"incomplete", status.incomplete},
              {"lost", status.lost},
              {"late", status.late}}
      .dump();
}

std::string encode_camera_calibration(const CameraIntrinsics& camera, std::string_view frame_id,
                                      std::int64_t timestamp_ns) {
  const auto& d = camera.distortion;
  return json{
      {"timestamp", time_json(timestamp_ns)},
      {"frame_id", frame_id},
      {"width", camera.width},
      {"height", camera.height},
      {"distortion_model", "plumb_bob"},
      {"D", {d[0], d[1], d[2], d[3], d[4]}},
      {"K", {camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0}},
      {"R", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}},
      {"P", {camera.fx, 0.0, camera.cx, 0.0, 0.0, camera.fy, camera.cy, 0.0, 0.0, 0.0, 1.0, 0.0}}}
      .dump();
}

std::string encode_color_pose(const RigCalibration& rig, std::string_view depth_frame_id,
                              std::string_view color_frame_id, std::int64_t timestamp_ns) {
  // P_d = R^T P_c - R^T T: the colour frame's rotation and origin in the depth frame.
  const cv::Matx33d rotation = rig.depth_to_color_r.t();
  const cv::Vec3d origin_mm = -(rotation * rig.depth_to_color_t_mm);
  const auto [x, y, z, w] = quaternion(rotation);
  return json{{"timestamp", time_json(timestamp_ns)},
              {"parent_frame_id", depth_frame_id},
              {"child_frame_id", color_frame_id},
              {"translation",
               {{"x", origin_mm[0] * kMetresPerMm},
                {"y", origin_mm[1] * kMetresPerMm},
                {"z", origin_mm[2] * kMetresPerMm}}},
              {"rotation", {{"x", x}, {"y", y}, {"z", z}, {"w", w}}}}
      .dump();
}

}  // namespace tilth::mcap
