// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320) as MCAP uses it for chunks,
// attachments, the data section and the summary; incremental. zlib's.
#pragma once

#include <cstdint>
#include <string_view>

namespace tilth::mcap {

// Continues `crc` (0 to start) over `bytes`.
std::uint32_t crc32(std::string_view bytes, std::uint32_t crc = 0);

}  // namespace tilth::mcap
