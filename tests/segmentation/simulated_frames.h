// Frames of the scene simulator as a segmentation stage receives them: synthetic.scene,
// depth.projection and registration.projective, loaded from the built plugins and run in
// this process, with each frame's ground truth.
#pragma once

#include <string>
#include <vector>

#include "framework/stage_registry.h"
#include "registered_frames.h"
#include "source_tree.h"

namespace tilth::segmentation {

inline const std::string kCalibration = testing::paper_rig_path().string();

inline std::vector<train_segmenter::RegisteredFrame> simulated_frames(const std::string& preset,
                                                                      int seed, int count) {
  // Loaded once and never unloaded: the frames' messages were made by the plugins' code.
  static const StageRegistry* registry = [] {
    auto* loaded = new StageRegistry;
    for (const char* plugin :
         {TILTH_SYNTHETIC_PLUGIN, TILTH_DEPTH_PLUGIN, TILTH_REGISTRATION_PLUGIN}) {
      loaded->load(plugin);
    }
    return loaded;
  }();
  train_segmenter::RegisteredFrames source(
      *registry, "synthetic.scene",
      {{"preset", preset}, {"seed", seed}, {"frames", count}, {"calibration", kCalibration}},
      kCalibration);
  std::vector<train_segmenter::RegisteredFrame> frames;
  while (auto frame = source.next()) frames.push_back(std::move(*frame));
  return frames;
}

}  // namespace tilth::segmentation
