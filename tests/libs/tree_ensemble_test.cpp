// The flattened trees decide as OpenCV's own predict() does, for a random forest and for
// boosted trees, on samples they were not trained on; and a tree deeper than the flat
// layout holds is refused.
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/ml.hpp>

#include "pixel_classifier/tree_ensemble.h"
#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

// Two overlapping classes in 6 features: label 1 where a noisy combination is positive.
void samples(int count, int seed, cv::Mat& features, cv::Mat& labels) {
  features.create(count, 6, CV_32F);
  cv::RNG(seed).fill(features, cv::RNG::NORMAL, 0.0, 1.0);
  labels.create(count, 1, CV_32S);
  cv::RNG noise(seed + 100);
  for (int i = 0; i < count; ++i) {
    const float* f = features.ptr<float>(i);
    labels.at<int>(i) = f[0] * f[1] + f[2] - 0.5f * f[3] + noise.gaussian(0.5) > 0 ? 1 : 0;
  }
}

void expect_same_decisions(const cv::ml::DTrees& trees, ClassifierKind kind) {
  const TreeEnsemble ensemble(trees, kind);
  cv::Mat features, labels;
  samples(3000, 2, features, labels);
  std::vector<float> scores(features.rows);
  ensemble.score(features.ptr<float>(), features.cols, scores.size(), scores.data());
  int residue = 0;
  for (int i = 0; i < features.rows; ++i) {
    const bool ours = scores[i] > 0;
    const bool opencv = trees.predict(features.row(i)) == 1.0f;
    ASSERT_EQ(ours, opencv) << "sample " << i;
    residue += ours;
  }
  // Both classes decided, so that the comparison means something.
  EXPECT_GT(residue, 300);
  EXPECT_LT(residue, 2700);
}

TEST(TreeEnsemble, DecidesAsOpenCVForAForest) {
  cv::Mat features, labels;
  samples(2000, 1, features, labels);
  auto forest = cv::ml::RTrees::create();
  forest->setMaxDepth(8);
  forest->setTermCriteria({cv::TermCriteria::MAX_ITER, 20, 0});  // even: ties happen
  forest->train(cv::ml::TrainData::create(features, cv::ml::ROW_SAMPLE, labels));
  expect_same_decisions(*forest, ClassifierKind::kForest);
}

TEST(TreeEnsemble, DecidesAsOpenCVForBoostedTrees) {
  cv::Mat features, labels;
  samples(2000, 1, features, labels);
  auto boost = cv::ml::Boost::create();
  boost->setWeakCount(30);
  boost->setMaxDepth(3);
  boost->train(cv::ml::TrainData::create(features, cv::ml::ROW_SAMPLE, labels));
  expect_same_decisions(*boost, ClassifierKind::kBoosted);
}

// 2^17 samples on a line whose labels alternate: a tree that separates them needs 2^17
// leaves, so 17 levels or more.
TEST(TreeEnsemble, RefusesATreeDeeperThanItHolds) {
  const int count = 1 << (TreeEnsemble::kMaxDepth + 1);
  cv::Mat features(count, 1, CV_32F), labels(count, 1, CV_32S);
  for (int i = 0; i < count; ++i) {
    features.at<float>(i) = static_cast<float>(i);
    labels.at<int>(i) = i % 2;
  }
  auto tree = cv::ml::DTrees::create();
  tree->setMaxDepth(TreeEnsemble::kMaxDepth + 4);
  tree->setMinSampleCount(2);
  tree->setCVFolds(0);
  tree->train(cv::ml::TrainData::create(features, cv::ml::ROW_SAMPLE, labels));
  EXPECT_THROW(TreeEnsemble(*tree, ClassifierKind::kForest), Error);
}

}  // namespace
}  // namespace tilth::segmentation
