// The outputs' rows (ResidueKernels::write_residue_row) at every instruction-set level this
// CPU runs, against the rule of residue_kernels.h applied pixel by pixel, on rows whose
// widths leave partial vectors and words; and every kernel on rows that end where the
// readable memory ends, so that a read or write past a row's end crashes the test.
#include "residue_kernels.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "color_range_table.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::segmentation {
namespace {

bool bit(const std::vector<std::uint64_t>& bits, int x) { return (bits[x / 64] >> (x % 64)) & 1; }

TEST(ResidueKernels, WriteResidueRowFollowsTheMaskRuleAtEveryLevel) {
  std::mt19937 random(7);
  for (const int cols : {640, 613, 64, 13}) {
    const auto words = static_cast<std::size_t>((cols + 63) / 64);
    std::vector<std::uint64_t> unknown(words), residue(words);
    for (std::size_t w = 0; w < words; ++w) {
      unknown[w] = (std::uint64_t{random()} << 32) | random();
      residue[w] = (std::uint64_t{random()} << 32) | random();
    }
    std::vector<float> depth(static_cast<std::size_t>(cols));
    std::uniform_real_distribution<float> mm(400.0f, 600.0f);
    for (int x = 0; x < cols; ++x) {
      depth[x] = random() % 5 == 0 ? std::numeric_limits<float>::quiet_NaN() : mm(random);
    }

    for (const ResidueKernels* kernels : available_residue_kernels()) {
      std::vector<std::uint8_t> mask(static_cast<std::size_t>(cols), 1);
      std::vector<float> soil(static_cast<std::size_t>(cols), -1.0f);
      std::memset(mask.data(), 1, static_cast<std::size_t>(cols));
      kernels->write_residue_row(unknown.data(), residue.data(), depth.data(), cols, mask.data(),
                                 soil.data());
      int wrong = 0, soil_pixels = 0;
      for (int x = 0; x < cols; ++x) {
        const bool is_unknown = bit(unknown, x) || std::isnan(depth[x]);
        const bool is_soil = !is_unknown && !bit(residue, x);
        const std::uint8_t expected = is_unknown ? ResidueMask::kUnknown
                                      : is_soil  ? ResidueMask::kSoil
                                                 : ResidueMask::kResidue;
        wrong += mask[x] != expected ? 1 : 0;
        wrong += is_soil ? (soil[x] != depth[x] ? 1 : 0) : (std::isnan(soil[x]) ? 0 : 1);
        soil_pixels += is_soil ? 1 : 0;
      }
      EXPECT_EQ(wrong, 0) << kernels->level << ", " << cols << " px";
      EXPECT_GT(soil_pixels, 0) << kernels->level << ", " << cols << " px";
    }
  }
}

// Bytes followed by a page that may not be touched: end() is the first byte of it.
class GuardedBytes {
 public:
  explicit GuardedBytes(std::size_t size)
      : page_(static_cast<std::size_t>(sysconf(_SC_PAGESIZE))),
        mapped_((size + page_ - 1) / page_ * page_ + page_),
        base_(static_cast<std::uint8_t*>(
            mmap(nullptr, mapped_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0))),
        size_(size) {
    if (base_ == MAP_FAILED) throw std::bad_alloc();
    mprotect(base_ + mapped_ - page_, page_, PROT_NONE);
  }
  ~GuardedBytes() { munmap(base_, mapped_); }
  GuardedBytes(const GuardedBytes&) = delete;
  GuardedBytes& operator=(const GuardedBytes&) = delete;

  // The last `size` bytes before the guard page.
  std::uint8_t* data() { return base_ + mapped_ - page_ - size_; }

 private:
  std::size_t page_;
  std::size_t mapped_;
  std::uint8_t* base_;
  std::size_t size_;
};

TEST(ResidueKernels, NoKernelReadsOrWritesPastARowsEnd) {
  // Runs of blues (hsv) and a byte per colour (lab), each with some colours in its box.
  const ColorRangeTable runs(cv::COLOR_BGR2HSV, {18, 40, 50}, {40, 255, 255});
  const ColorRangeTable bytes(cv::COLOR_BGR2Lab, {50, 110, 140}, {255, 132, 255});
  ASSERT_TRUE(runs.held_as_runs());
  ASSERT_FALSE(bytes.held_as_runs());
  std::mt19937 random(3);
  for (const int cols : {613, 37, 13, 1}) {
    const auto words = static_cast<std::size_t>((cols + 63) / 64);
    GuardedBytes bgr(3 * static_cast<std::size_t>(cols));
    for (int i = 0; i < 3 * cols; ++i) bgr.data()[i] = static_cast<std::uint8_t>(random());
    GuardedBytes depth(sizeof(float) * static_cast<std::size_t>(cols));
    const float mm = 500.0f;
    for (int x = 0; x < cols; ++x) std::memcpy(depth.data() + sizeof mm * x, &mm, sizeof mm);
    GuardedBytes mask(static_cast<std::size_t>(cols));
    GuardedBytes soil(sizeof(float) * static_cast<std::size_t>(cols));
    std::vector<std::uint64_t> in_range(words), unknown(words, 0);

    for (const ResidueKernels* kernels : available_residue_kernels()) {
      for (const ColorRangeTable* table : {&runs, &bytes}) {
        table->classify_row(*kernels, bgr.data(), cols, in_range.data());
        int wrong = 0;
        for (int x = 0; x < cols; ++x) {
          const std::uint8_t* pixel = bgr.data() + 3 * x;
          const bool bit = (in_range[x / 64] >> (x % 64)) & 1;
          wrong += bit != table->contains(pixel[0], pixel[1], pixel[2]) ? 1 : 0;
        }
        EXPECT_EQ(wrong, 0) << kernels->level << ", " << cols << " px";
      }
      std::memset(mask.data(), 1, static_cast<std::size_t>(cols));
      kernels->write_residue_row(unknown.data(), in_range.data(),
                                 reinterpret_cast<const float*>(depth.data()), cols, mask.data(),
                                 reinterpret_cast<float*>(soil.data()));
      EXPECT_NE(mask.data()[cols - 1], 1) << kernels->level;  // written: a mask code
    }
  }
}

}  // namespace
}  // namespace tilth::segmentation
