// Leave-one-recording-out scoring: each recording scored by a model trained on all the
// others, so that every figure is of a place the model has not seen.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "segmenter_training.h"

namespace tilth::train_segmenter {

// For each recording i (at least two): a model of `options` trained on the samples of every
// recording but i, and `score(i, model)`, in recording order. Throws tilth::Error when the
// other recordings lack a class.
std::vector<Scores> leave_one_recording_out(
    const std::vector<TrainingSet>& recordings, const ClassifierOptions& options,
    const std::function<Scores(std::size_t, const segmentation::ClassifierModel&)>& score);

}  // namespace tilth::train_segmenter
