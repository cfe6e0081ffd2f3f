// The lines of a small text file of a recording (frames.csv, host_timestamps.csv), read
// whole and safely: a regular file only, at most a given size, each line at most a given
// length; errors name the file and line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace tilth::recording {

class TextLines {
 public:
  struct Limits {
    std::uint64_t file_bytes;
    std::size_t line_bytes;
  };

  // Throws tilth::Error naming the file when it is not a regular file or is too large.
  TextLines(const std::filesystem::path& file, Limits limits, std::string_view what);

  // The next line without its "\n" (and a "\r" before it, from Windows), or false at the
  // end. Throws tilth::Error naming the file and line when the line is too long.
  bool next(std::string_view& line);
  // The number of the line `next` gave, from 1.
  std::size_t number() const { return number_; }

 private:
  const std::filesystem::path file_;
  const Limits limits_;
  const std::string text_;
  std::size_t position_ = 0;
  std::size_t number_ = 0;
};

}  // namespace tilth::recording
