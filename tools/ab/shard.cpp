#include "shard.h"

#include <charconv>

#include "tilth/error.h"

namespace tilth::ab {
namespace {

// Shards beyond this are not a fleet's machines but a mistake.
constexpr std::size_t kMaxShards = 100000;

bool read_whole(std::string_view text, std::size_t& value) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  return !text.empty() && error == std::errc() && stop == end;
}

}  // namespace

Shard parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  Shard shard;
  if (slash == std::string::npos ||
      !read_whole(std::string_view(text).substr(0, slash), shard.index) ||
      !read_whole(std::string_view(text).substr(slash + 1), shard.count) || shard.count == 0 ||
      shard.count > kMaxShards || shard.index >= shard.count) {
    throw Error("--shard " + text + ": expected I/N, the shard I of N (0 <= I < N <= " +
                std::to_string(kMaxShards) + "), e.g. 0/4");
  }
  return shard;
}

}  // namespace tilth::ab
