// A trained cv::ml random forest or boosted trees flattened into complete binary trees
// (a shorter branch extended to the tree's depth), so that every pixel of a frame is scored
// without OpenCV's per-sample overhead and without a branch per level; it decides as the
// model's own predict() does (test TreeEnsemble.DecidesAsOpenCV).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <opencv2/ml.hpp>

namespace tilth::segmentation {

enum class ClassifierKind { kForest, kBoosted };

class TreeEnsemble {
 public:
  // A complete tree of d levels holds 2^d leaves: 16 levels take 768 KiB.
  static constexpr int kMaxDepth = 16;

  // `trees`: a trained cv::ml::RTrees (kForest) or cv::ml::Boost (kBoosted) classifier of
  // the labels 0 (soil) and 1 (residue) over float features (which OpenCV splits as
  // ordered values, never as categories). Throws tilth::Error for a tree deeper than
  // kMaxDepth.
  TreeEnsemble(const cv::ml::DTrees& trees, ClassifierKind kind);

  // The scores of `count` samples whose features start `stride` floats apart; above 0 for
  // residue. A forest: its residue votes minus its soil votes (a tie is soil, as OpenCV's
  // first most-voted class); boosted trees: the sum of the trees' values. Tree by tree over
  // all samples, so that a tree's nodes stay in the cache.
  void score(const float* features, std::size_t stride, std::size_t count, float* scores) const;

 private:
  struct Split {
    std::int32_t feature;
    float threshold;  // features[feature] <= threshold: go left
  };
  static constexpr std::size_t kLanes = 8;

  struct Tree {
    int depth;
    std::size_t splits, leaves;  // where its 2^depth - 1 splits and 2^depth leaves start
  };
  // Adds the leaves that `kSamples` samples reach to their scores; `leaf`: the tree's
  // leaves, indexed by slot.
  template <std::size_t kSamples>
  static void descend(const Split* split, const float* leaf, int depth, const float* features,
                      std::size_t stride, float* scores);

  std::vector<Split> splits_;  // each tree's in breadth-first order: children of i at 2i+1, 2i+2
  std::vector<float> leaves_;  // a leaf's vote (+1 residue, -1 soil) or boosted value
  std::vector<Tree> trees_;
};

}  // namespace tilth::segmentation
