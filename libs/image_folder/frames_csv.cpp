#include "image_folder/frames_csv.h"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string_view>

#include "image_folder/text_lines.h"
#include "tilth/error.h"
#include "tilth/regular_file.h"

namespace tilth::recording {
namespace {

namespace fs = std::filesystem;

enum Column { kIndex, kDepthTimestamp, kColorTimestamp, kDepth, kColor, kMask, kGroundTruth };
constexpr std::array<std::string_view, 7> kColumnNames{
    "index", "depth_timestamp_ns", "color_timestamp_ns", "depth", "color",
    "mask",  "ground_truth_mm"};
constexpr std::size_t kRequiredColumns = 5;  // index .. color; mask and ground truth optional

// The comma-separated fields of `line` into `fields`, whose storage is reused line after line.
void split(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  for (;;) {
    const auto comma = line.find(',');
    fields.push_back(line.substr(0, comma));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

const std::string& expected_columns() {
  static const std::string text = [] {
    std::string columns;
    for (std::size_t c = 0; c < kColumnNames.size(); ++c) {
      columns += (c == 0                  ? ""
                  : c == kRequiredColumns ? " and optionally "
                                          : ", ") +
                 std::string(kColumnNames[c]);
    }
    return "expected columns " + columns;
  }();
  return text;
}

// Reads one line's fields, naming the file and line in every error.
class LineReader {
 public:
  LineReader(const fs::path& file, std::size_t line) : file_(file), line_(line) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(file_.string() + ":" + std::to_string(line_) + ": " + message);
  }
  [[noreturn]] void fail(Column column, const std::string& expected, std::string_view got) const {
    fail("column '" + std::string(kColumnNames[column]) + "': expected " + expected + ", got '" +
         std::string(got) + "'");
  }

  template <class Integer>
  Integer integer(Column column, std::string_view text, const std::string& expected) const {
    Integer value{};
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error == std::errc::result_out_of_range) {
      fail(column,
           expected + " from " + std::to_string(std::numeric_limits<Integer>::min()) + " to " +
               std::to_string(std::numeric_limits<Integer>::max()),
           text);
    }
    if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
      fail(column, expected, text);
    }
    return value;
  }

  std::optional<double> optional_number(Column column, std::string_view text) const {
    if (text.empty()) return std::nullopt;
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
      fail(column, "a number of millimetres or nothing", text);
    }
    return value;
  }

  std::string path(Column column, std::string_view text) const {
    if (text.empty()) fail(column, "a file path relative to the recording folder", text);
    return std::string(text);
  }

 private:
  const fs::path& file_;
  const std::size_t line_;
};

// Where each known column is in the file's header.
using ColumnPositions = std::array<std::optional<std::size_t>, kColumnNames.size()>;

ColumnPositions read_header(const fs::path& file, std::string_view header) {
  const LineReader reader(file, 1);
  ColumnPositions positions;
  std::vector<std::string_view> names;
  split(header, names);
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::size_t c = 0;
    while (c < kColumnNames.size() && kColumnNames[c] != names[i]) ++c;
    if (c == kColumnNames.size()) {
      reader.fail("unknown column '" + std::string(names[i]) + "' (" + expected_columns() + ")");
    }
    if (positions[c]) reader.fail("column '" + std::string(names[i]) + "' appears twice");
    positions[c] = i;
  }
  for (std::size_t c = 0; c < kRequiredColumns; ++c) {
    if (!positions[c]) {
      reader.fail("missing required column '" + std::string(kColumnNames[c]) + "' (" +
                  expected_columns() + ")");
    }
  }
  return positions;
}

// Indices and each camera's timestamps strictly increase: the frames are in capture order
// and each is there once.
template <class Value>
void check_increasing(const LineReader& reader, Column column, Value previous, Value current,
                      std::size_t previous_line) {
  if (current <= previous) {
    reader.fail(
        column,
        "a value > " + std::to_string(previous) + " (line " + std::to_string(previous_line) + ")",
        std::to_string(current));
  }
}

}  // namespace

std::vector<FrameEntry> read_frames_csv(const fs::path& file) {
  if (!fs::exists(file)) throw Error(file.string() + ": cannot read (is this a recording folder?)");
  TextLines lines(file, {kMaxFramesCsvBytes, kMaxFramesCsvLine}, "frames.csv");
  std::string_view text;
  if (!lines.next(text))
    throw Error(file.string() + ":1: expected the header line, got an empty file");
  const ColumnPositions positions = read_header(file, text);
  std::vector<std::string_view> fields;
  split(text, fields);
  const std::size_t field_count = fields.size();

  std::vector<FrameEntry> entries;
  while (lines.next(text)) {
    const std::size_t line = lines.number();
    if (text.empty()) continue;
    if (entries.size() == kMaxFrames) {
      throw Error(file.string() + ":" + std::to_string(line) + ": more than " +
                  std::to_string(kMaxFrames) + " frames; expected at most that many");
    }
    const LineReader reader(file, line);
    split(text, fields);
    if (fields.size() != field_count) {
      reader.fail("expected " + std::to_string(field_count) + " fields as in the header, got " +
                  std::to_string(fields.size()));
    }
    const auto field = [&](Column column) {
      return positions[column] ? fields[*positions[column]] : std::string_view();
    };
    FrameEntry entry;
    entry.line = line;
    entry.index = reader.integer<std::uint64_t>(kIndex, field(kIndex), "a non-negative integer");
    entry.depth_timestamp_ns = reader.integer<std::int64_t>(kDepthTimestamp, field(kDepthTimestamp),
                                                            "an integer number of nanoseconds");
    entry.color_timestamp_ns = reader.integer<std::int64_t>(kColorTimestamp, field(kColorTimestamp),
                                                            "an integer number of nanoseconds");
    entry.depth = reader.path(kDepth, field(kDepth));
    entry.color = reader.path(kColor, field(kColor));
    entry.mask = std::string(field(kMask));
    entry.ground_truth_mm = reader.optional_number(kGroundTruth, field(kGroundTruth));
    if (!entries.empty()) {
      const FrameEntry& previous = entries.back();
      check_increasing(reader, kIndex, previous.index, entry.index, previous.line);
      check_increasing(reader, kDepthTimestamp, previous.depth_timestamp_ns,
                       entry.depth_timestamp_ns, previous.line);
      check_increasing(reader, kColorTimestamp, previous.color_timestamp_ns,
                       entry.color_timestamp_ns, previous.line);
    }
    entries.push_back(std::move(entry));
  }
  return entries;
}

std::string frames_csv_line(const FrameEntry& entry) {
  std::string ground_truth;
  if (entry.ground_truth_mm) {
    // The shortest text that reads back as the same double, with at least two decimals.
    // 400 characters hold any finite double in fixed notation.
    std::array<char, 400> buffer{};
    const auto end = std::to_chars(buffer.data(), buffer.data() + buffer.size(),
                                   *entry.ground_truth_mm, std::chars_format::fixed)
                         .ptr;
    ground_truth.assign(buffer.data(), end);
    if (ground_truth.find('.') == std::string::npos) ground_truth += ".";
    const std::size_t decimals = ground_truth.size() - ground_truth.find('.') - 1;
    if (decimals < 2) ground_truth.append(2 - decimals, '0');
  }
  return std::to_string(entry.index) + "," + std::to_string(entry.depth_timestamp_ns) + "," +
         std::to_string(entry.color_timestamp_ns) + "," + entry.depth + "," + entry.color + "," +
         entry.mask + "," + ground_truth;
}

std::string frame_file_name(std::uint64_t index) {
  std::ostringstream name;
  name << std::setw(6) << std::setfill('0') << index << ".png";
  return name.str();
}

void rewrite_mask_column(const fs::path& file, const std::map<std::size_t, std::string>& masks) {
  const std::string text = read_regular_file(file, kMaxFramesCsvBytes, "frames.csv");
  std::string rewritten;
  rewritten.reserve(text.size() + 32 * masks.size());
  std::optional<std::size_t> mask_position;  // none: the column is added at the end
  std::size_t number = 0;
  std::vector<std::string_view> fields;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t newline = text.find('\n', start);
    const std::size_t next = newline == std::string::npos ? text.size() : newline + 1;
    std::string_view line = std::string_view(text).substr(start, next - start);
    start = next;
    ++number;
    // The line's end ("\n", "\r\n" or nothing) is kept as it was.
    std::string_view end = line;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    end.remove_prefix(line.size());
    split(line, fields);
    if (number == 1) {
      for (std::size_t i = 0; i < fields.size(); ++i) {
        if (fields[i] == kColumnNames[kMask]) mask_position = i;
      }
      rewritten.append(line).append(mask_position ? "" : ",mask").append(end);
      continue;
    }
    const auto mask = masks.find(number);
    if (line.empty() || (mask == masks.end() && mask_position)) {
      rewritten.append(line).append(end);
      continue;
    }
    const std::string value = mask == masks.end() ? "" : mask->second;
    if (!mask_position) {
      rewritten.append(line).append(",").append(value).append(end);
      continue;
    }
    for (std::size_t i = 0; i < fields.size(); ++i) {
      rewritten.append(i == 0 ? "" : ",").append(i == *mask_position ? value : fields[i]);
    }
    rewritten.append(end);
  }
  fs::path temporary = file;
  temporary += ".new";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << rewritten;
    out.close();
    if (!out) throw Error(temporary.string() + ": cannot write");
  }
  std::error_code error;
  fs::rename(temporary, file, error);
  if (error) {
    fs::remove(temporary);
    throw Error(file.string() + ": cannot replace with " + temporary.string() + ": " +
                error.message());
  }
}

}  // namespace tilth::recording
