#include "image_folder/host_timestamps_csv.h"

#include <charconv>
#include <optional>

#include "image_folder/text_lines.h"
#include "tilth/error.h"

namespace tilth::recording {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxLineBytes = 64;

struct Line {
  std::uint64_t index = 0;
  std::int64_t host_timestamp_ns = 0;
};

template <class Integer>
std::optional<Integer> parse_integer(std::string_view text) {
  Integer value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

class LineReader {
 public:
  LineReader(const fs::path& file, std::size_t line) : file_(file), line_(line) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(file_.string() + ":" + std::to_string(line_) + ": " + message);
  }

  Line read(std::string_view text) const {
    const auto comma = text.find(',');
    if (comma == std::string_view::npos || text.find(',', comma + 1) != std::string_view::npos) {
      fail("expected 2 fields (" + std::string(kHostTimestampsHeader) + "), got '" +
           std::string(text) + "'");
    }
    const std::string_view index = text.substr(0, comma);
    const std::string_view host = text.substr(comma + 1);
    const auto parsed_index = parse_integer<std::uint64_t>(index);
    if (!parsed_index) {
      fail("column 'index': expected a non-negative integer, got '" + std::string(index) + "'");
    }
    const auto parsed_host = parse_integer<std::int64_t>(host);
    if (!parsed_host || *parsed_host < 0) {
      fail(
          "column 'host_timestamp_ns': expected a non-negative integer number of nanoseconds, "
          "got '" +
          std::string(host) + "'");
    }
    return {*parsed_index, *parsed_host};
  }

 private:
  const fs::path& file_;
  const std::size_t line_;
};

}  // namespace

std::vector<std::int64_t> read_host_timestamps(const fs::path& file,
                                               const std::vector<FrameEntry>& frames) {
  // One line per frame of frames.csv, of at most two 20-digit numbers, and one more.
  TextLines lines(file, {(kMaxFrames + 2) * kMaxLineBytes, kMaxLineBytes}, "host_timestamps.csv");
  std::string_view text;
  if (!lines.next(text)) {
    throw Error(file.string() + ":1: expected the header '" + std::string(kHostTimestampsHeader) +
                "', got an empty file");
  }
  if (text != kHostTimestampsHeader) {
    LineReader(file, 1).fail("expected the header '" + std::string(kHostTimestampsHeader) +
                             "', got '" + std::string(text) + "'");
  }

  std::vector<std::int64_t> host_timestamps;
  bool after_last_frame = false;
  while (lines.next(text)) {
    const std::size_t line = lines.number();
    if (text.empty()) continue;
    const LineReader reader(file, line);
    const Line read = reader.read(text);
    if (host_timestamps.size() < frames.size()) {
      const FrameEntry& frame = frames[host_timestamps.size()];
      if (read.index != frame.index) {
        reader.fail("column 'index': expected " + std::to_string(frame.index) +
                    ", the index on frames.csv line " + std::to_string(frame.line) + ", got '" +
                    std::to_string(read.index) + "'");
      }
      host_timestamps.push_back(read.host_timestamp_ns);
    } else if (after_last_frame) {
      reader.fail(
          "expected at most one line after the last frame of frames.csv (one a killed "
          "writer wrote), got a second");
    } else {
      if (!frames.empty() && read.index <= frames.back().index) {
        reader.fail("column 'index': expected a value > " + std::to_string(frames.back().index) +
                    " (the last frame, frames.csv line " + std::to_string(frames.back().line) +
                    "), got '" + std::to_string(read.index) + "'");
      }
      after_last_frame = true;
    }
  }
  if (host_timestamps.size() < frames.size()) {
    const FrameEntry& next = frames[host_timestamps.size()];
    throw Error(file.string() + ": ends after " + std::to_string(host_timestamps.size()) +
                " frames; expected a line for each of the " + std::to_string(frames.size()) +
                " frames of frames.csv, the next for index " + std::to_string(next.index) +
                " (frames.csv line " + std::to_string(next.line) + ")");
  }
  return host_timestamps;
}

std::string host_timestamps_line(std::uint64_t index, std::int64_t host_timestamp_ns) {
  return std::to_string(index) + "," + std::to_string(host_timestamp_ns);
}

}  // namespace tilth::recording
