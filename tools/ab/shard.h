// One deterministic part of a comparison's (variant, recording) jobs, for running a
// comparison on several machines (`tilth ab --shard I/N`, then `tilth ab merge`): job j
// belongs to shard j mod N, so every shard gets variants and recordings alike.
#pragma once

#include <cstddef>
#include <string>

namespace tilth::ab {

struct Shard {
  std::size_t index = 0;
  std::size_t count = 1;

  bool contains(std::size_t job) const { return job % count == index; }
  std::string text() const { return std::to_string(index) + "/" + std::to_string(count); }
};

// Reads "I/N" (0 <= I < N, both whole numbers). Throws tilth::Error saying what was
// expected.
Shard parse_shard(const std::string& text);

}  // namespace tilth::ab
