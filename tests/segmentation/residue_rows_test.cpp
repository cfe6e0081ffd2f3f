// The per-pixel bit tests against their one-pixel definitions, for every byte value at
// every position of a word and every run length up to a mask word.
#include "residue_rows.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>

#include "tilth/messages/registered_color.h"

namespace tilth::segmentation {
namespace {

constexpr int kWord = 64;

std::uint64_t marked_one_by_one(const std::uint8_t* bytes, int count) {
  std::uint64_t bits = 0;
  for (int i = 0; i < count; ++i) bits |= std::uint64_t{bytes[i] >= 128} << i;
  return bits;
}

std::uint64_t valid_one_by_one(const std::uint8_t* status, int count) {
  std::uint64_t bits = 0;
  for (int i = 0; i < count; ++i) {
    bits |= std::uint64_t{status[i] == RegisteredColor::kValid} << i;
  }
  return bits;
}

TEST(ResidueRows, EveryByteValueAtEveryPositionGivesItsOwnBit) {
  std::array<std::uint8_t, kWord> bytes{};
  for (int position = 0; position < kWord; ++position) {
    for (int value = 0; value < 256; ++value) {
      bytes.fill(0);
      bytes[position] = static_cast<std::uint8_t>(value);
      const std::uint64_t bit = std::uint64_t{1} << position;
      ASSERT_EQ(marked_bits(bytes.data(), kWord), value >= 128 ? bit : 0)
          << "byte " << value << " at " << position;
      bytes.fill(RegisteredColor::kValid ^ 1);
      bytes[position] = static_cast<std::uint8_t>(value);
      ASSERT_EQ(valid_status_bits(bytes.data(), kWord), value == RegisteredColor::kValid ? bit : 0)
          << "status " << value << " at " << position;
    }
  }
}

TEST(ResidueRows, RandomRunsOfEveryLengthMatchOnePixelAtATime) {
  std::mt19937 random(7);
  // Statuses drawn mostly from near kValid, where a carry between bytes would show.
  std::uniform_int_distribution<int> near_valid(RegisteredColor::kValid - 2,
                                                RegisteredColor::kValid + 2);
  std::uniform_int_distribution<int> any_byte(0, 255);
  std::array<std::uint8_t, kWord + 1> bytes{};  // + 1: a run need not start on a word
  for (int round = 0; round < 2000; ++round) {
    for (auto& byte : bytes)
      byte = static_cast<std::uint8_t>(round % 2 ? any_byte(random) : near_valid(random) & 0xff);
    for (int count = 0; count <= kWord; ++count) {
      const std::uint8_t* start = bytes.data() + round % 2;
      ASSERT_EQ(marked_bits(start, count), marked_one_by_one(start, count)) << count;
      ASSERT_EQ(valid_status_bits(start, count), valid_one_by_one(start, count)) << count;
    }
  }
}

}  // namespace
}  // namespace tilth::segmentation
