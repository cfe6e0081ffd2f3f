#include "image_folder/text_lines.h"

#include <algorithm>

#include "tilth/error.h"
#include "tilth/regular_file.h"

namespace tilth::recording {

TextLines::TextLines(const std::filesystem::path& file, Limits limits, std::string_view what)
    : file_(file), limits_(limits), text_(read_regular_file(file, limits.file_bytes, what)) {}

bool TextLines::next(std::string_view& line) {
  if (position_ >= text_.size()) return false;
  const std::size_t end = std::min(text_.find('\n', position_), text_.size());
  line = std::string_view(text_).substr(position_, end - position_);
  position_ = end + 1;
  ++number_;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (line.size() > limits_.line_bytes) {
    throw Error(file_.string() + ":" + std::to_string(number_) + ": a line of " +
                std::to_string(line.size()) + " bytes; expected at most " +
                std::to_string(limits_.line_bytes));
  }
  return true;
}

}  // namespace tilth::recording
