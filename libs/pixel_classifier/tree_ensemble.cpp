#include "pixel_classifier/tree_ensemble.h"

#include <algorithm>
#include <array>
#include <limits>
#include <string>

#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

// A split that sends every finite value left: a leaf above the last level passes its
// value down the left branch.
constexpr float kAlwaysLeft = std::numeric_limits<float>::infinity();

int depth_below(const std::vector<cv::ml::DTrees::Node>& nodes, int node) {
  if (nodes[node].split < 0) return 0;
  return 1 + std::max(depth_below(nodes, nodes[node].left), depth_below(nodes, nodes[node].right));
}

}  // namespace

template <std::size_t kSamples>
void TreeEnsemble::descend(const Split* split, const float* leaf, int depth, const float* features,
                           std::size_t stride, float* scores) {
  std::array<std::size_t, kSamples> slot{};
  for (int level = 0; level < depth; ++level) {
    for (std::size_t i = 0; i < kSamples; ++i) {
      const Split& at = split[slot[i]];
      slot[i] = 2 * slot[i] + 1 + (features[i * stride + at.feature] > at.threshold ? 1 : 0);
    }
  }
  for (std::size_t i = 0; i < kSamples; ++i) scores[i] += leaf[slot[i]];
}

TreeEnsemble::TreeEnsemble(const cv::ml::DTrees& trees, ClassifierKind kind) {
  const auto& nodes = trees.getNodes();
  const auto& splits = trees.getSplits();
  for (const int root : trees.getRoots()) {
    const int depth = depth_below(nodes, root);
    if (depth > kMaxDepth) {
      throw Error("a tree of " + std::to_string(depth) + " levels (at most " +
                  std::to_string(kMaxDepth) + ")");
    }
    const std::size_t first_leaf = (std::size_t{1} << depth) - 1;
    const Tree tree{depth, splits_.size(), leaves_.size()};
    splits_.resize(splits_.size() + first_leaf, Split{0, kAlwaysLeft});
    leaves_.resize(leaves_.size() + first_leaf + 1, 0.0f);
    // Each OpenCV node into its slot of the complete tree.
    const auto place = [&](const auto& self, int node, std::size_t slot) -> void {
      const cv::ml::DTrees::Node& at = nodes[node];
      if (at.split >= 0) {
        const cv::ml::DTrees::Split& split = splits.at(at.split);
        splits_[tree.splits + slot] = {split.varIdx, split.c};
        self(self, at.left, 2 * slot + 1);
        self(self, at.right, 2 * slot + 2);
      } else if (slot < first_leaf) {
        self(self, node, 2 * slot + 1);
      } else if (kind == ClassifierKind::kForest) {
        leaves_[tree.leaves + slot - first_leaf] = at.classIdx == 1 ? 1.0f : -1.0f;
      } else {
        leaves_[tree.leaves + slot - first_leaf] = static_cast<float>(at.value);
      }
    };
    place(place, root, 0);
    trees_.push_back(tree);
  }
}

void TreeEnsemble::score(const float* features, std::size_t stride, std::size_t count,
                         float* scores) const {
  std::fill(scores, scores + count, 0.0f);
  for (const Tree& tree : trees_) {
    const Split* split = splits_.data() + tree.splits;
    const float* leaf = leaves_.data() + tree.leaves - ((std::size_t{1} << tree.depth) - 1);
    // Samples descend kLanes at a time, level by level: their paths do not wait for each
    // other's loads.
    std::size_t first = 0;
    for (; first + kLanes <= count; first += kLanes) {
      descend<kLanes>(split, leaf, tree.depth, features + first * stride, stride, scores + first);
    }
    for (; first < count; ++first) {
      descend<1>(split, leaf, tree.depth, features + first * stride, stride, scores + first);
    }
  }
}

}  // namespace tilth::segmentation
