// Chunk compression as MCAP names it: "zstd", "lz4" (the LZ4 frame format) or "".
#pragma once

#include <string>
#include <string_view>

namespace tilth::mcap {

std::string compress(std::string_view compression, std::string_view bytes);
// Throws tilth::Error naming `where` when the data is not valid or not `size` bytes.
std::string decompress(std::string_view compression, std::string_view bytes, std::size_t size,
                       const std::string& where);

}  // namespace tilth::mcap
