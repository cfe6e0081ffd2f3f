#include "base64.h"

#include <array>

#include "tilth/error.h"

namespace tilth::mcap {
namespace {

constexpr std::string_view kAlphabet =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
constexpr std::uint8_t kInvalid = 0xFF;

constexpr std::array<std::uint8_t, 256> make_values() {
  std::array<std::uint8_t, 256> values{};
  values.fill(kInvalid);
  for (std::size_t i = 0; i < kAlphabet.size(); ++i) {
    values[static_cast<unsigned char>(kAlphabet[i])] = static_cast<std::uint8_t>(i);
  }
  return values;
}

constexpr std::array<std::uint8_t, 256> kValues = make_values();

// The two characters of every 12-bit value: half the lookups of one per character.
constexpr std::array<std::array<char, 2>, 4096> make_pairs() {
  std::array<std::array<char, 2>, 4096> pairs{};
  for (std::size_t i = 0; i < pairs.size(); ++i)
    pairs[i] = {kAlphabet[i >> 6], kAlphabet[i & 0x3F]};
  return pairs;
}

constexpr std::array<std::array<char, 2>, 4096> kPairs = make_pairs();

}  // namespace

void append_base64(std::string& out, std::string_view bytes) {
  const std::size_t start = out.size();
  out.resize(start + (bytes.size() + 2) / 3 * 4);
  char* next = out.data() + start;
  const auto* in = reinterpret_cast<const unsigned char*>(bytes.data());
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t word = (in[i] << 16) | (in[i + 1] << 8) | in[i + 2];
    const auto& high = kPairs[word >> 12];
    const auto& low = kPairs[word & 0xFFF];
    next[0] = high[0];
    next[1] = high[1];
    next[2] = low[0];
    next[3] = low[1];
    next += 4;
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const std::uint32_t word = (in[i] << 16) | (two ? in[i + 1] << 8 : 0);
    *next++ = kAlphabet[word >> 18];
    *next++ = kAlphabet[(word >> 12) & 0x3F];
    *next++ = two ? kAlphabet[(word >> 6) & 0x3F] : '=';
    *next++ = '=';
  }
}

std::string decode_base64(std::string_view text, const std::string& where) {
  if (text.size() % 4 != 0) {
    throw Error(where + ": base64 data of " + std::to_string(text.size()) +
                " characters; expected a multiple of 4");
  }
  std::size_t padding = 0;
  if (!text.empty() && text.back() == '=') ++padding;
  if (text.size() > 1 && text[text.size() - 2] == '=') ++padding;
  std::string out(text.size() / 4 * 3 - padding, '\0');
  std::size_t written = 0;
  for (std::size_t i = 0; i < text.size(); i += 4) {
    std::uint32_t word = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = text[i + k];
      std::uint8_t value = kValues[static_cast<unsigned char>(c)];
      if (c == '=' && i + k >= text.size() - padding) value = 0;
      if (value == kInvalid) {
        throw Error(where + ": base64 data has '" + std::string(1, c) + "' at character " +
                    std::to_string(i + k));
      }
      word = (word << 6) | value;
    }
    for (int shift = 16; shift >= 0 && written < out.size(); shift -= 8) {
      out[written++] = static_cast<char>((word >> shift) & 0xFF);
    }
  }
  return out;
}

}  // namespace tilth::mcap
