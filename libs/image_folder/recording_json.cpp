#include "image_folder/recording_json.h"

#include <array>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth::recording {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::array kRecordingColorFormats{PixelFormat::kBgr8, PixelFormat::kBayerRggb8,
                                            PixelFormat::kBayerBggr8, PixelFormat::kBayerGrbg8,
                                            PixelFormat::kBayerGbrg8};

std::string shortened(const json& value) {
  std::string text = value.dump();
  return text.size() > 60 ? text.substr(0, 57) + "..." : text;
}

[[noreturn]] void fail(const fs::path& file, const std::string& pointer,
                       const std::string& expected, const json& got) {
  throw Error(file.string() + ":" + pointer + ": expected " + expected + ", got " + shortened(got));
}

const json& required(const json& document, const fs::path& file, const std::string& key) {
  const auto it = document.find(key);
  if (it == document.end()) throw Error(file.string() + ":/" + key + ": missing required field");
  return *it;
}

RigCalibration read_calibration(const json& value, const fs::path& folder, const fs::path& file) {
  if (value.is_object()) return parse_calibration(value, file.string() + ":/calibration");
  if (!value.is_string() || value.get<std::string>().empty()) {
    fail(file, "/calibration",
         "a calibration file name relative to the folder, or a calibration object", value);
  }
  return load_calibration(folder / value.get<std::string>());
}

// {"x", "y", "width", "height"}: whole numbers, a window inside the calibrated image.
cv::Rect read_color_window(const json& value, const CameraIntrinsics& color, const fs::path& file) {
  const std::string expected =
      "{\"x\", \"y\", \"width\", \"height\"} in pixels, inside the calibration's " +
      std::to_string(color.width) + "x" + std::to_string(color.height) + " px colour image";
  if (!value.is_object() || value.size() != 4) fail(file, "/color_window", expected, value);
  std::array<int, 4> numbers{};
  const std::array<const char*, 4> names{"x", "y", "width", "height"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto it = value.find(names[i]);
    if (it == value.end() || !it->is_number_integer() || it->get<std::int64_t>() < 0 ||
        it->get<std::int64_t>() > 1'000'000) {
      fail(file, "/color_window", expected, value);
    }
    numbers[i] = it->get<int>();
  }
  const cv::Rect window(numbers[0], numbers[1], numbers[2], numbers[3]);
  if (window.empty() || (window & cv::Rect(0, 0, color.width, color.height)) != window) {
    fail(file, "/color_window", expected, value);
  }
  return window;
}

}  // namespace

bool is_recording_color_format(PixelFormat format) {
  for (PixelFormat allowed : kRecordingColorFormats) {
    if (allowed == format) return true;
  }
  return false;
}

std::string recording_color_formats() {
  std::string names;
  for (PixelFormat format : kRecordingColorFormats) {
    names += (names.empty() ? "" : ", ") + std::string(to_string(format));
  }
  return names;
}

RecordingJson read_recording_json(const fs::path& folder) {
  const fs::path file = folder / "recording.json";
  if (!fs::exists(file)) throw Error(file.string() + ": cannot read (is this a recording folder?)");
  const json document = parse_json(read_json_text(file, "recording.json"), file.string());
  if (!document.is_object()) fail(file, "", "an object", document);
  for (const auto& [key, value] : document.items()) {
    if (key != "format" && key != "calibration" && key != "color_format" && key != "description" &&
        key != "tags" && key != "color_window") {
      throw Error(file.string() + ":/" + key + ": no such field (misspelt?)");
    }
  }

  const json& format = required(document, file, "format");
  if (format != std::string(kFormat))
    fail(file, "/format", "\"" + std::string(kFormat) + "\"", format);

  RecordingJson recording;
  const json& color_format = required(document, file, "color_format");
  const auto parsed =
      color_format.is_string() ? parse_pixel_format(color_format.get<std::string>()) : std::nullopt;
  if (!parsed || !is_recording_color_format(*parsed)) {
    fail(file, "/color_format", "one of " + recording_color_formats(), color_format);
  }
  recording.color_format = *parsed;

  if (const auto it = document.find("description"); it != document.end()) {
    if (!it->is_string()) fail(file, "/description", "a string", *it);
    recording.description = it->get<std::string>();
  }
  if (const auto it = document.find("tags"); it != document.end()) {
    if (!it->is_object())
      fail(file, "/tags", "an object of strings, e.g. {\"site\": \"north\"}", *it);
    for (const auto& [key, value] : it->items()) {
      if (!value.is_string()) fail(file, "/tags/" + key, "a string", value);
      recording.tags[key] = value.get<std::string>();
    }
  }
  recording.calibration = read_calibration(required(document, file, "calibration"), folder, file);
  if (const auto it = document.find("color_window"); it != document.end()) {
    recording.color_window = read_color_window(*it, recording.calibration.color, file);
  }
  return recording;
}

void write_recording_json(const fs::path& folder, const std::string& calibration_file,
                          PixelFormat color_format, const std::string& description,
                          const std::optional<cv::Rect>& color_window) {
  json document = {{"format", std::string(kFormat)},
                   {"calibration", calibration_file},
                   {"color_format", std::string(to_string(color_format))},
                   {"description", description}};
  if (color_window) {
    document["color_window"] = {{"x", color_window->x},
                                {"y", color_window->y},
                                {"width", color_window->width},
                                {"height", color_window->height}};
  }
  const fs::path file = folder / "recording.json";
  const fs::path temporary = folder / "recording.json.tmp";
  {
    std::ofstream out(temporary);
    out << document.dump(2) << "\n";
    out.close();
    if (!out) throw Error(temporary.string() + ": cannot write");
  }
  fs::rename(temporary, file);
}

}  // namespace tilth::recording
