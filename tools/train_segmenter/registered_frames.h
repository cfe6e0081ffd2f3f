// Frames of a recording (or the simulator) as a segmentation stage receives them: a source
// stage, depth projection and registration, made from the loaded plugins and run in this
// process one frame at a time, with each frame's ground truth. The trainer and the
// segmentation tests read their pixels through it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "framework/stage_registry.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/registered_color.h"

namespace tilth::train_segmenter {

struct RegisteredFrame {
  std::uint64_t frame_id = 0;
  std::shared_ptr<const RegisteredColor> color;
  std::shared_ptr<const DepthImage> depth;
  std::shared_ptr<const GroundTruth> truth;
};

class RegisteredFrames {
 public:
  // `source_type` must output `raw`, `color` and `truth` (recording.image_folder,
  // synthetic.scene); `source_params` are its parameters, the rest default. Throws
  // tilth::Error naming the stage that cannot be made.
  RegisteredFrames(const StageRegistry& registry, const std::string& source_type,
                   const nlohmann::json& source_params, const std::filesystem::path& calibration);
  ~RegisteredFrames();
  RegisteredFrames(const RegisteredFrames&) = delete;
  RegisteredFrames& operator=(const RegisteredFrames&) = delete;

  // The next frame; empty at the end of the stream.
  std::optional<RegisteredFrame> next();

 private:
  class Chain;
  std::unique_ptr<Chain> chain_;
};

}  // namespace tilth::train_segmenter
