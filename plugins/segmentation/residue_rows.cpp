#include "residue_rows.h"

#include <opencv2/core/hal/intrin.hpp>

#include "tilth/messages/registered_color.h"

namespace tilth::segmentation {

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

}  // namespace tilth::segmentation
