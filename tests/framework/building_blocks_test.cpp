// The runtime's building blocks on their own: admission, keyed join, reordering,
// latency histogram, name suggestions.
#include <atomic>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "framework/bundle.h"
#include "framework/frame_admission.h"
#include "framework/keyed_join.h"
#include "framework/latency_histogram.h"
#include "framework/nearest_names.h"
#include "framework/sequence_reorder.h"

namespace tilth {
namespace {

std::shared_ptr<Bundle> bundle_for(std::size_t node, std::uint64_t frame_id) {
  auto bundle = std::make_shared<Bundle>();
  bundle->node = node;
  bundle->info.frame_id = frame_id;
  return bundle;
}

TEST(FrameAdmission, AssemblesOneBundlePerSourceWithDenseSequences) {
  std::vector<std::pair<std::uint64_t, std::vector<std::uint64_t>>> admitted;
  FrameAdmission admission(
      2, 10, FullPolicy::kBlock,
      [&](std::uint64_t sequence, std::vector<std::shared_ptr<Bundle>> b) {
        admitted.push_back({sequence, {b[0]->info.frame_id, b[1]->info.frame_id}});
      });
  EXPECT_TRUE(admission.offer(0, bundle_for(0, 10)));
  EXPECT_TRUE(admitted.empty());  // waits for source 1
  EXPECT_TRUE(admission.offer(1, bundle_for(1, 20)));
  EXPECT_TRUE(admission.offer(1, bundle_for(1, 21)));
  EXPECT_TRUE(admission.offer(0, bundle_for(0, 11)));
  ASSERT_EQ(admitted.size(), 2u);
  EXPECT_EQ(admitted[0], (std::pair<std::uint64_t, std::vector<std::uint64_t>>{0, {10, 20}}));
  EXPECT_EQ(admitted[1], (std::pair<std::uint64_t, std::vector<std::uint64_t>>{1, {11, 21}}));
  EXPECT_EQ(admission.in_flight(), 2u);
}

TEST(FrameAdmission, DropOldestKeepsTheNewestWaitingFrame) {
  std::vector<std::uint64_t> admitted;
  FrameAdmission admission(1, 1, FullPolicy::kDropOldest,
                           [&](std::uint64_t, std::vector<std::shared_ptr<Bundle>> b) {
                             admitted.push_back(b[0]->info.frame_id);
                           });
  for (std::uint64_t id = 0; id < 5; ++id) EXPECT_TRUE(admission.offer(0, bundle_for(0, id)));
  EXPECT_EQ(admitted, (std::vector<std::uint64_t>{0}));
  EXPECT_EQ(admission.dropped(), 3u);  // 1, 2, 3 replaced; 4 waits
  admission.complete();
  EXPECT_EQ(admitted, (std::vector<std::uint64_t>{0, 4}));
}

TEST(FrameAdmission, BlockHoldsTheSourceUntilAFrameCompletes) {
  std::atomic<int> admitted{0};
  FrameAdmission admission(
      1, 1, FullPolicy::kBlock,
      [&](std::uint64_t, std::vector<std::shared_ptr<Bundle>>) { ++admitted; });
  std::atomic<int> offered{0};
  std::thread source([&] {
    for (int i = 0; i < 3; ++i) {
      admission.offer(0, bundle_for(0, i));
      ++offered;
    }
  });
  // Frame 0 is admitted, frame 1 waits, the offer of frame 2 blocks.
  while (offered.load() < 2) std::this_thread::yield();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(offered.load(), 2);
  EXPECT_EQ(admitted.load(), 1);
  admission.complete();
  source.join();
  EXPECT_EQ(admitted.load(), 2);
  EXPECT_EQ(admission.dropped(), 0u);
}

TEST(FrameAdmission, EndOfStreamAdmitsWhatWaitsThenCloses) {
  int admitted = 0;
  FrameAdmission admission(
      1, 1, FullPolicy::kBlock,
      [&](std::uint64_t, std::vector<std::shared_ptr<Bundle>>) { ++admitted; });
  admission.offer(0, bundle_for(0, 0));
  admission.offer(0, bundle_for(0, 1));
  admission.end_of_stream(0);
  admission.complete();
  EXPECT_EQ(admitted, 2);
  admission.complete();
  admission.wait_until_drained();  // returns: closed and nothing in flight
  EXPECT_FALSE(admission.offer(0, bundle_for(0, 2)));
}

TEST(KeyedJoin, CompletesWhenEverySlotHasArrived) {
  KeyedJoin join(3);
  EXPECT_FALSE(join.add(7, 2, bundle_for(2, 7)));
  EXPECT_FALSE(join.add(8, 0, bundle_for(0, 8)));
  EXPECT_FALSE(join.add(7, 0, bundle_for(0, 7)));
  const auto complete = join.add(7, 1, bundle_for(1, 7));
  ASSERT_TRUE(complete);
  EXPECT_EQ((*complete)[0]->node, 0u);
  EXPECT_EQ((*complete)[1]->node, 1u);
  EXPECT_EQ((*complete)[2]->node, 2u);
  EXPECT_EQ(join.pending(), 1u);
}

TEST(KeyedJoin, ConcurrentArrivalsCompleteEachFrameOnce) {
  constexpr int kFrames = 2000;
  KeyedJoin join(2);
  std::atomic<int> completed{0};
  auto feed = [&](std::size_t slot) {
    std::vector<int> order(kFrames);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), std::minstd_rand(static_cast<unsigned>(slot + 1)));
    for (int frame : order) {
      if (join.add(frame, slot, bundle_for(slot, frame))) ++completed;
    }
  };
  std::thread a(feed, 0);
  std::thread b(feed, 1);
  a.join();
  b.join();
  EXPECT_EQ(completed.load(), kFrames);
  EXPECT_EQ(join.pending(), 0u);
}

TEST(SequenceReorder, ReleasesInOrder) {
  SequenceReorder<int> reorder;
  EXPECT_TRUE(reorder.push(2, 20).empty());
  EXPECT_TRUE(reorder.push(1, 10).empty());
  EXPECT_EQ(reorder.push(0, 0), (std::vector<int>{0, 10, 20}));
  EXPECT_EQ(reorder.push(3, 30), (std::vector<int>{30}));
  EXPECT_EQ(reorder.waiting(), 0u);
}

TEST(LatencyHistogram, PercentilesWithinBucketResolution) {
  LatencyHistogram histogram;
  for (int us = 1; us <= 1000; ++us) histogram.record(us * 1000);  // 1..1000 us
  const LatencySummary summary = histogram.summary();
  EXPECT_EQ(summary.count, 1000u);
  EXPECT_NEAR(summary.mean_ms, 0.5005, 1e-9);
  EXPECT_DOUBLE_EQ(summary.max_ms, 1.0);
  // 16 buckets per octave: a bucket is at most 1/16 of its value wide.
  EXPECT_NEAR(summary.p50_ms, 0.500, 0.500 / 16);
  EXPECT_NEAR(summary.p99_ms, 0.990, 0.990 / 16);
}

TEST(NearestNames, SuggestsCloseNamesOnly) {
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(nearest_names("depth.projektion", {"depth.projection", "sinks.csv", "depth.x"}),
            (std::vector<std::string>{"depth.projection"}));
  EXPECT_EQ(did_you_mean("zzzzzz", {"depth.projection"}), "");
  EXPECT_EQ(did_you_mean("ab", {"ac", "ad", "xyz"}), "; did you mean 'ac' or 'ad'?");
}

}  // namespace
}  // namespace tilth
