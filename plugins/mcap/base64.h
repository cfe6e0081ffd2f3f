// Base64 (RFC 4648, with padding), as JSON carries the bytes of a foxglove.RawImage.
#pragma once

#include <string>
#include <string_view>

namespace tilth::mcap {

// Appends the encoding of `bytes` to `out`.
void append_base64(std::string& out, std::string_view bytes);
// Throws tilth::Error naming `where` at the first character that is not base64.
std::string decode_base64(std::string_view text, const std::string& where);

}  // namespace tilth::mcap
