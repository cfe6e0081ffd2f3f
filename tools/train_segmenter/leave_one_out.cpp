#include "leave_one_out.h"

#include <string>

#include "tilth/error.h"

namespace tilth::train_segmenter {

std::vector<Scores> leave_one_recording_out(
    const std::vector<TrainingSet>& recordings, const ClassifierOptions& options,
    const std::function<Scores(std::size_t, const segmentation::ClassifierModel&)>& score) {
  if (recordings.size() < 2) {
    throw Error("leave-one-recording-out of " + std::to_string(recordings.size()) +
                " recording(s) (expected at least 2)");
  }
  std::vector<Scores> scores;
  for (std::size_t held_out = 0; held_out < recordings.size(); ++held_out) {
    TrainingSet others(recordings[held_out].features());
    for (std::size_t i = 0; i < recordings.size(); ++i) {
      if (i != held_out) others.add(recordings[i]);
    }
    try {
      scores.push_back(score(
          held_out, others.train(options, "all but recording " + std::to_string(held_out + 1))));
    } catch (const Error& error) {
      throw Error("without recording " + std::to_string(held_out + 1) + ": " + error.what());
    }
  }
  return scores;
}

}  // namespace tilth::train_segmenter
