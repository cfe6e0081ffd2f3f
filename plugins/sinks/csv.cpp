// Writes one CSV row per frame: the frame, its capture times, the ground distance with
// its validity, the cause when invalid, its quality, the latency from capture, the
// ground truth when a truth input is connected, and the Tilth release that measured it.
// Each row is one write(2), so a killed process loses at most the row being written. A
// row the disk does not take (full) is cut back off the file, reported as lost data, and
// the rows after it are written when the disk takes them: the file only ever holds whole
// rows. With rotation by size or age, rows go on in numbered files (run.csv, run.1.csv,
// run.2.csv, ...), each starting with the header (docs/sinks.md).
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>

#include <fcntl.h>
#include <unistd.h>

#include "tilth/messages/ground_distance.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/plugin.h"
#include "tilth/version.h"

namespace tilth::sinks {
namespace {

constexpr std::string_view kHeader =
    "index,device_timestamp_ns,host_timestamp_ns,distance_mm,valid,cause,soil_fraction,"
    "soil_pixels,spread_mm,confidence,held_ms,latency_ms,truth_mm,tilth_version\n";

// File `number` of a rotated series: the path itself, then "<stem>.<number><extension>".
std::filesystem::path numbered(const std::filesystem::path& path, std::uint64_t number) {
  if (number == 0) return path;
  return path.parent_path() /
         (path.stem().string() + "." + std::to_string(number) + path.extension().string());
}

class Csv final : public Sink {
 public:
  enum Port { kDistance = 0, kTruth = 1 };
  using Clock = std::chrono::steady_clock;

  explicit Csv(const StageContext& context)
      : path_(context.params.path("path")),
        rotate_bytes_(static_cast<std::uint64_t>(context.params.integer("rotate_bytes"))),
        rotate_after_(std::chrono::seconds(context.params.integer("rotate_seconds"))),
        log_(context.log),
        report_data_loss_(context.report_data_loss) {
    if (path_.has_parent_path()) {
      std::error_code error;
      std::filesystem::create_directories(path_.parent_path(), error);
      if (error) {
        throw Error(path_.string() + ": cannot create its directory " +
                    path_.parent_path().string() + ": " + error.message());
      }
    }
    if (!open()) {
      throw Error(current_.string() + ": " + write_error_ +
                  " (parameter 'path' must name a file in a writable directory)");
    }
  }
  ~Csv() override {
    if (file_ >= 0) ::close(file_);
  }

  void consume(const Frame& frame) override {
    const auto& distance = frame.input<GroundDistance>(kDistance);
    const auto& info = frame.info();
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    const double latency_ms = (std::chrono::duration_cast<std::chrono::nanoseconds>(now).count() -
                               info.host_timestamp_ns) *
                              1e-6;
    std::string truth;
    if (!frame.input(kTruth).empty()) {
      const auto& known = frame.input<GroundTruth>(kTruth);
      if (known.distance_mm) truth = format("%.3f", *known.distance_mm);
    }
    const std::string held =
        distance.valid && distance.held ? format("%.1f", distance.held_ms) : std::string();
    const std::string row =
        format("%llu,%lld,%lld,%.3f,%d,%s,%.4f,%lld,%.3f,%.3f,",
               static_cast<unsigned long long>(info.frame_id),
               static_cast<long long>(info.device_timestamp_ns),
               static_cast<long long>(info.host_timestamp_ns),
               distance.valid ? distance.distance_mm : std::nan(""), distance.valid ? 1 : 0,
               distance.valid ? "" : to_string(distance.cause).data(), distance.soil_fraction,
               static_cast<long long>(distance.soil_pixels), distance.spread_mm,
               distance.confidence) +
        held + format(",%.3f,", latency_ms) + truth + "," + std::string(version()) + "\n";
    if (file_ >= 0 && full_before(row)) {
      ++number_;
      close();  // when this throws, the next row still goes to the next file
    }
    // A file whose header the disk did not take gets it with its first row.
    if ((file_ >= 0 || open()) && append(bytes_in_file_ == 0 ? std::string(kHeader) + row : row)) {
      ++rows_in_file_;
      if (lost_in_a_row_ > 0) report_resumed();
    } else {
      lose(info.frame_id);
    }
  }

  void finish() override {
    if (lost_in_a_row_ > 0) {
      log_.warning(current_.string() + ": the last " + std::to_string(lost_in_a_row_) +
                   " row(s) were not written; " + std::to_string(rows_lost_) + " lost in all");
    }
  }

 private:
  template <class... Args>
  static std::string format(const char* pattern, Args... args) {
    char line[512];
    const int length = std::snprintf(line, sizeof line, pattern, args...);
    return std::string(line, static_cast<std::size_t>(std::max(length, 0)));
  }

  // A file holds at least one row, so a row larger than rotate_bytes still gets written.
  bool full_before(const std::string& row) const {
    if (rows_in_file_ == 0) return false;
    if (rotate_bytes_ > 0 && bytes_in_file_ + row.size() > rotate_bytes_) return true;
    return rotate_after_.count() > 0 && Clock::now() - opened_at_ >= rotate_after_;
  }

  // Opens the next file of the series and writes its header; false with the error in
  // write_error_. O_APPEND: after a row is cut back off, the next one goes where it began.
  bool open() {
    current_ = numbered(path_, number_);
    file_ = ::open(current_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0666);
    if (file_ < 0) {
      write_error_ = std::string("cannot open for writing: ") + std::strerror(errno);
      return false;
    }
    opened_at_ = Clock::now();
    bytes_in_file_ = 0;
    rows_in_file_ = 0;
    append(std::string(kHeader));
    return true;
  }

  void close() {
    if (::close(std::exchange(file_, -1)) != 0) {
      throw Error(current_.string() + ": close failed: " + std::strerror(errno));
    }
  }

  // Writes `text` whole, or cuts the file back to its last whole line and returns false
  // with the error in write_error_.
  bool append(const std::string& text) {
    std::size_t written = 0;
    while (written < text.size()) {
      const ssize_t count = ::write(file_, text.data() + written, text.size() - written);
      if (count < 0 && errno == EINTR) continue;
      if (count <= 0) break;
      written += static_cast<std::size_t>(count);
    }
    if (written == text.size()) {
      bytes_in_file_ += text.size();
      return true;
    }
    write_error_ = std::strerror(errno);
    if (written > 0 && ::ftruncate(file_, static_cast<off_t>(bytes_in_file_)) != 0) {
      write_error_ +=
          std::string("; cutting the partial row back off failed too: ") + std::strerror(errno);
    }
    return false;
  }

  void lose(std::uint64_t frame_id) {
    if (lost_in_a_row_++ == 0) first_lost_ = frame_id;
    last_lost_ = frame_id;
    ++rows_lost_;
    report_data_loss_(1, current_.string() + ": " + write_error_ + "; the row of frame " +
                             std::to_string(frame_id) + " was not written (" +
                             std::to_string(rows_lost_) +
                             " row(s) lost so far); rows are written again when the disk takes "
                             "them");
  }

  void report_resumed() {
    log_.warning(current_.string() + ": writing rows again; " + std::to_string(lost_in_a_row_) +
                 " row(s) lost (frames " + std::to_string(first_lost_) + " to " +
                 std::to_string(last_lost_) + "), " + std::to_string(rows_lost_) + " in all");
    lost_in_a_row_ = 0;
  }

  const std::filesystem::path path_;
  const std::uint64_t rotate_bytes_;
  const std::chrono::seconds rotate_after_;
  std::uint64_t number_ = 0;
  std::filesystem::path current_;
  const Logger log_;
  const std::function<void(std::uint64_t, const std::string&)> report_data_loss_;
  int file_ = -1;
  Clock::time_point opened_at_;
  std::uint64_t bytes_in_file_ = 0;
  std::uint64_t rows_in_file_ = 0;
  std::string write_error_;
  std::uint64_t rows_lost_ = 0;
  std::uint64_t lost_in_a_row_ = 0;  // since the last row written
  std::uint64_t first_lost_ = 0;     // frame ids of the first and last of those
  std::uint64_t last_lost_ = 0;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "sinks.csv";
  d.summary = "one CSV row per frame: ground distance, validity, quality, latency, truth";
  d.inputs = {PortSpec::of<GroundDistance>("distance", "the measurement"),
              PortSpec::of<GroundTruth>("truth", "ground truth, when known").optional()};
  d.params = {
      ParamSpec::output_path("path", std::nullopt).describe("CSV file to write (replaced)"),
      ParamSpec::integer("rotate_bytes", 0)
          .range(0, std::nullopt)
          .in_unit("bytes")
          .describe("start the next numbered file before one grows past this; 0 = never"),
      ParamSpec::integer("rotate_seconds", 0)
          .range(0, std::nullopt)
          .in_unit("s")
          .describe("start the next numbered file when one is this old; 0 = never"),
  };
  d.create = factory<Csv>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::sinks
