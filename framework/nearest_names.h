// Suggestions for a misspelt name: the known names closest to it by edit distance.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace tilth {

std::size_t edit_distance(std::string_view a, std::string_view b);

// Up to `limit` candidates within a distance that scales with the word's length,
// closest first.
std::vector<std::string> nearest_names(std::string_view word,
                                       const std::vector<std::string>& candidates,
                                       std::size_t limit = 3);

// "; did you mean 'a' or 'b'?" or "" when nothing is close.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

// "'a', 'b', 'c'"
std::string quoted_list(const std::vector<std::string>& names);

}  // namespace tilth
