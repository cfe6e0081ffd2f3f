// The frame pairs `tilth calibrate capture` looks at, through the runtime and the plugins
// a graph uses: from an image-folder recording whose depth images hold the ToF intensity,
// or live from the two GigE Vision cameras, the ToF camera streaming its Intensity
// component, paired by capture time.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "framework/runtime.h"

namespace tilth::calibrate {

struct FramePair {
  std::uint64_t frame_id = 0;
  cv::Mat intensity;  // CV_16UC1, as the ToF camera sent it
  cv::Mat color;      // CV_8UC3 BGR (a Bayer mosaic demosaiced), or CV_8UC1 grey
};

// Cameras as aravis.tof_camera and aravis.color_camera name them (address, serial, ...).
struct LiveCameras {
  std::string tof;
  std::string color;
};

using PairSource = std::variant<std::filesystem::path, LiveCameras>;

// A parameter of one of the graph's nodes from the command line (`--set tof.exposure_us=800`),
// typed as `tilth run --set` types it. The nodes: `recording`, or `tof`, `color` and `pair`.
struct NodeSetting {
  std::string node;
  std::string param;
  std::string value;
  std::string option;  // as given, for messages
};

struct PairStream {
  PairSource source;
  std::vector<NodeSetting> settings;
  std::optional<std::uint64_t> max_frames;
};

// Hands each pair to `on_pair`, in capture order, until the source ends, `max_frames`
// pairs, a stop signal, or `on_pair` returns false. A live source drops pairs while
// `on_pair` is busy. Throws tilth::Error when a setting names no node or parameter, a
// stage cannot start (no recording, no camera) or the run fails, naming the node.
RunResult look_at_pairs(const PairStream& stream,
                        const std::function<bool(const FramePair&)>& on_pair);

}  // namespace tilth::calibrate
