#include "residue_rows.h"

#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "tilth/messages/registered_color.h"

namespace tilth::segmentation {
namespace {

// Sixteen pixels' bytes at a time, GCC vector extensions.
constexpr int kLanes = 16;
using Bytes = std::uint8_t __attribute__((vector_size(kLanes)));

Bytes bytes_at(const std::uint8_t* bytes) {
  Bytes vector;
  std::memcpy(&vector, bytes, sizeof vector);
  return vector;
}

// Bit k set where byte k has its high bit set: one instruction on x86-64 (SSE2), which
// vector extensions cannot express.
std::uint64_t high_bits(Bytes bytes) {
#if defined(__SSE2__)
  return static_cast<std::uint16_t>(_mm_movemask_epi8(reinterpret_cast<__m128i>(bytes)));
#else
  std::uint64_t bits = 0;
  for (int k = 0; k < kLanes; ++k) bits |= std::uint64_t{bytes[k] >> 7} << k;
  return bits;
#endif
}

}  // namespace

std::uint64_t marked_bits(const std::uint8_t* bytes, int count) {
  std::uint64_t bits = 0;
  int i = 0;
  for (; i + kLanes <= count; i += kLanes) bits |= high_bits(bytes_at(bytes + i)) << i;
  for (; i < count; ++i) bits |= std::uint64_t{bytes[i] >= 128} << i;
  return bits;
}

std::uint64_t valid_status_bits(const std::uint8_t* status, int count) {
  const Bytes valid_status = Bytes{} + std::uint8_t{RegisteredColor::kValid};
  std::uint64_t bits = 0;
  int i = 0;
  for (; i + kLanes <= count; i += kLanes) {
    const Bytes valid = reinterpret_cast<Bytes>(bytes_at(status + i) == valid_status);
    bits |= high_bits(valid) << i;
  }
  for (; i < count; ++i) bits |= std::uint64_t{status[i] == RegisteredColor::kValid} << i;
  return bits;
}

}  // namespace tilth::segmentation
