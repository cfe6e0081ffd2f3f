// The live view's one web page: self-contained (no file or library fetched from anywhere
// but this server), laid out for a phone or tablet as well as a desktop.
#pragma once

#include <string_view>

namespace tilth::view {

std::string_view page_html();

}  // namespace tilth::view
