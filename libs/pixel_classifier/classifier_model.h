// The model file of segmentation.pixel_classifier, written by tilth train-segmenter: a
// random forest over the pixel features, stored with the format version, the features
// and colour cells it was trained on, and how it was trained (docs/segmentation-variants.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/ml.hpp>

namespace tilth::segmentation {

inline constexpr std::string_view kClassifierFormat = "tilth-pixel-classifier/1";
// The class labels of the training responses.
inline constexpr int kSoilClass = 0;
inline constexpr int kResidueClass = 1;

// `training`: free text for people (recordings, samples, held-out figures).
void write_classifier_model(const std::filesystem::path& file, const cv::ml::RTrees& forest,
                            const std::string& training);

// Throws tilth::Error naming the file and what was expected: a missing or unreadable
// file, another format, other features or colour cells, no trained forest.
cv::Ptr<cv::ml::RTrees> read_classifier_model(const std::filesystem::path& file);

// The class the forest gives each colour cell: 255 residue, 0 soil.
std::vector<std::uint8_t> residue_by_cell(const cv::ml::StatModel& classifier);

}  // namespace tilth::segmentation
