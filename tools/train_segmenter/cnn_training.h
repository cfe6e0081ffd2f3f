// Training segmentation.cnn's network for tilth train-segmenter --model cnn: the frames
// made as for the pixel classifier (registered colour on the depth grid, the truth mask)
// written to a temporary folder, train_cnn.py (shipped in share/tilth/train-segmenter/)
// run on them with Debian's python3 and PyTorch, and the exported model scored with the
// stage's own code (ResidueNet) where it was not trained.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

#include "cnn_model/residue_net.h"
#include "registered_frames.h"
#include "segmenter_training.h"
#include "soil_surface/depth_labels.h"

namespace tilth::train_segmenter {

struct CnnOptions {
  std::uint64_t seed = 1;
  int epochs = 30;
  int steps = 40;  // batches of 8 windows per epoch
  bool leave_one_out = true;
  // The network's shape; unset: train_cnn.py's defaults (84x64 px, 0.25, 16,32,64).
  std::optional<cv::Size> input;      // px, multiples of 4
  std::optional<double> input_scale;  // network px per depth px
  std::optional<std::array<int, 3>> channels;
  // Train on labels from depth (segmentation::DepthLabels) instead of the masks; the
  // masks then only score.
  std::optional<segmentation::DepthLabelOptions> depth_labels;
};

// One recording's scores, as the pixel classifier's report has them.
struct CnnScoredRecording {
  std::string recording;
  Scores scores;
  std::uint64_t scored_frames = 0;  // 0: not scored (no mask)
  std::vector<std::string> trained_on;
};

struct CnnTraining {
  std::string scoring;                   // how the rows were scored
  std::vector<CnnScoredRecording> rows;  // empty: not scored (--no-leave-one-out)
};

using OpenRecording = std::function<RegisteredFrames(const std::string& recording)>;

// Trains on `recordings` and writes `out` (MODEL.onnx and MODEL.json). Scored on `tests`
// if any; else with one recording on its every 5th frame, held out; else leave one
// recording out unless options.leave_one_out is false. Throws tilth::Error naming what
// failed: no frame with a mask (or, labelled by depth, no pixel labelled), the Python training (its
// last lines; exit code 3: PyTorch missing), a model the stage cannot run.
CnnTraining train_cnn(const std::vector<std::string>& recordings,
                      const std::vector<std::string>& tests, const OpenRecording& open,
                      const CnnOptions& options, const std::filesystem::path& out);

// The residue decisions of the network on a whole frame, as the stage makes them on a
// window of window_scale: the frame covered by windows of the sidecar's input size /
// window_scale (the last row and column of windows flush with its edges).
void classify_frame(segmentation::ResidueNet& net, const cv::Mat& bgr, cv::Mat& residue);

// The network's scores on a frame (pixels with trusted colour and a soil or residue
// truth); empty when the frame has no ground-truth mask.
std::optional<Scores> score_cnn_frame(segmentation::ResidueNet& net, const RegisteredFrame& frame);

}  // namespace tilth::train_segmenter
