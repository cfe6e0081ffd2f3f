// Chunk compression as MCAP names it: "zstd", "lz4" (the LZ4 frame format) or "".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace tilth::mcap {

std::string compress(std::string_view compression, std::string_view bytes);
// Throws tilth::Error naming `where` when the data is not valid, not `size` bytes, or
// `size` is over kMaxChunkRecordsSize. Allocates as the data decompresses, not `size` up
// front, so a damaged size costs no memory.
std::string decompress(std::string_view compression, std::string_view bytes, std::uint64_t size,
                       const std::string& where);

}  // namespace tilth::mcap
