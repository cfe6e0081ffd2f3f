// Two numbers joined by a separator, as command lines write sizes ("640x480", "8x5") and
// ranges ("400:700").
#pragma once

#include <charconv>
#include <optional>
#include <string>
#include <system_error>
#include <utility>

namespace tilth::calibrate {

// The two numbers around the first `separator`; none unless the whole text is that.
template <class T>
std::optional<std::pair<T, T>> number_pair(const std::string& text, char separator) {
  const auto at = text.find(separator);
  if (at == std::string::npos) return std::nullopt;
  T first{};
  T second{};
  const char* middle = text.data() + at;
  const char* end = text.data() + text.size();
  const auto [first_end, first_error] = std::from_chars(text.data(), middle, first);
  const auto [second_end, second_error] = std::from_chars(middle + 1, end, second);
  if (first_error != std::errc() || first_end != middle || second_error != std::errc() ||
      second_end != end) {
    return std::nullopt;
  }
  return std::pair<T, T>(first, second);
}

}  // namespace tilth::calibrate
