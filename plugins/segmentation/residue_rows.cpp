#include "residue_rows.h"

#include <array>
#include <bit>
#include <cstring>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>

#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::segmentation {
namespace {

static_assert(std::endian::native == std::endian::little, "eight mask bytes are one word");

// Byte i of entry b is 0xFF where bit i of b is set.
constexpr std::array<std::uint64_t, 256> kByteMasks = [] {
  std::array<std::uint64_t, 256> masks{};
  for (unsigned bits = 0; bits < 256; ++bits) {
    for (int i = 0; i < 8; ++i) {
      if ((bits >> i) & 1) masks[bits] |= std::uint64_t{0xFF} << (8 * i);
    }
  }
  return masks;
}();

// Lane i of entry n is all ones where bit i of n is set.
constexpr std::array<std::array<std::uint32_t, 4>, 16> kLaneMasks = [] {
  std::array<std::array<std::uint32_t, 4>, 16> masks{};
  for (unsigned bits = 0; bits < 16; ++bits) {
    for (int i = 0; i < 4; ++i) masks[bits][i] = ((bits >> i) & 1) ? ~0u : 0u;
  }
  return masks;
}();

constexpr std::uint64_t every_byte(std::uint8_t value) { return value * 0x0101010101010101u; }

// All ones in lane i where bit i of `bits` is set; bits from 4 on are ignored.
cv::v_float32x4 lanes(unsigned bits) {
  return cv::v_reinterpret_as_f32(cv::v_load(kLaneMasks[bits & 15].data()));
}

}  // namespace

std::uint64_t marked_bits(const std::uint8_t* bytes, int count) {
  std::uint64_t bits = 0;
  int i = 0;
  for (; i + 16 <= count; i += 16) {
    const auto lanes = static_cast<std::uint32_t>(cv::v_signmask(cv::v_load(bytes + i)));
    bits |= std::uint64_t{lanes} << i;
  }
  for (; i < count; ++i) bits |= std::uint64_t{bytes[i] >= 128} << i;
  return bits;
}

std::uint64_t valid_status_bits(const std::uint8_t* status, int count) {
  std::uint64_t bits = 0;
  int i = 0;
  const cv::v_uint8x16 valid = cv::v_setall_u8(RegisteredColor::kValid);
  for (; i + 16 <= count; i += 16) {
    const auto lanes = static_cast<std::uint32_t>(cv::v_signmask(cv::v_load(status + i) == valid));
    bits |= std::uint64_t{lanes} << i;
  }
  for (; i < count; ++i) bits |= std::uint64_t{status[i] == RegisteredColor::kValid} << i;
  return bits;
}

void write_residue_row(const std::uint64_t* unknown, const std::uint64_t* residue,
                       const float* depth_mm, int cols, std::uint8_t* mask, float* soil_mm) {
  constexpr float kNoSoil = std::numeric_limits<float>::quiet_NaN();
  const cv::v_float32x4 no_soil = cv::v_setall_f32(kNoSoil);
  int x = 0;
  for (; x + 8 <= cols; x += 8) {  // eight pixels: one byte of each bit row
    const cv::v_float32x4 depth_low = cv::v_load(depth_mm + x);
    const cv::v_float32x4 depth_high = cv::v_load(depth_mm + x + 4);
    const auto missing = static_cast<unsigned>(cv::v_signmask(depth_low != depth_low) |
                                               cv::v_signmask(depth_high != depth_high) << 4);
    const unsigned marked_unknown = (unknown[x / 64] >> (x % 64)) & 0xFF;
    const unsigned marked_residue = (residue[x / 64] >> (x % 64)) & 0xFF;
    const unsigned unknown_bits = marked_unknown | missing;
    const unsigned residue_bits = marked_residue & ~unknown_bits;
    const unsigned soil_bits = ~(unknown_bits | residue_bits) & 0xFF;
    const std::uint64_t values = (kByteMasks[unknown_bits] & every_byte(ResidueMask::kUnknown)) |
                                 (kByteMasks[residue_bits] & every_byte(ResidueMask::kResidue)) |
                                 (kByteMasks[soil_bits] & every_byte(ResidueMask::kSoil));
    std::memcpy(mask + x, &values, sizeof values);
    cv::v_store(soil_mm + x, cv::v_select(lanes(soil_bits), depth_low, no_soil));
    cv::v_store(soil_mm + x + 4, cv::v_select(lanes(soil_bits >> 4), depth_high, no_soil));
  }
  for (; x < cols; ++x) {
    const bool is_unknown = ((unknown[x / 64] >> (x % 64)) & 1) || depth_mm[x] != depth_mm[x];
    const bool is_residue = (residue[x / 64] >> (x % 64)) & 1;
    mask[x] = is_unknown   ? ResidueMask::kUnknown
              : is_residue ? ResidueMask::kResidue
                           : ResidueMask::kSoil;
    soil_mm[x] = is_unknown || is_residue ? kNoSoil : depth_mm[x];
  }
}

}  // namespace tilth::segmentation
