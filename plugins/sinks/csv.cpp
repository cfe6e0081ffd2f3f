// Writes one CSV row per frame: the frame, its capture times, the ground distance with
// its validity, the cause when invalid, its quality, the latency from capture, and the ground truth
// when a truth input is connected. Every row is flushed, so a killed process loses at most the row
// being written. With rotation by size or age, rows go on in numbered files (run.csv, run.1.csv,
// run.2.csv, ...), each starting with the header (docs/sinks.md).
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>

#include "tilth/messages/ground_distance.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/plugin.h"

namespace tilth::sinks {
namespace {

constexpr std::string_view kHeader =
    "index,device_timestamp_ns,host_timestamp_ns,distance_mm,valid,cause,soil_fraction,"
    "soil_pixels,spread_mm,confidence,latency_ms,truth_mm\n";

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
        rotate_after_(std::chrono::seconds(context.params.integer("rotate_seconds"))) {
    if (path_.has_parent_path()) {
      std::error_code error;
      std::filesystem::create_directories(path_.parent_path(), error);
      if (error) {
        throw Error(path_.string() + ": cannot create its directory " +
                    path_.parent_path().string() + ": " + error.message());
      }
    }
    open();
  }
  ~Csv() override {
    if (file_ != nullptr) std::fclose(file_);
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
    const std::string row =
        format("%llu,%lld,%lld,%.3f,%d,%s,%.4f,%lld,%.3f,%.3f,%.3f,",
               static_cast<unsigned long long>(info.frame_id),
               static_cast<long long>(info.device_timestamp_ns),
               static_cast<long long>(info.host_timestamp_ns),
               distance.valid ? distance.distance_mm : std::nan(""), distance.valid ? 1 : 0,
               distance.valid ? "" : to_string(distance.cause).data(), distance.soil_fraction,
               static_cast<long long>(distance.soil_pixels), distance.spread_mm,
               distance.confidence, latency_ms) +
        truth + "\n";
    if (file_ != nullptr && full_before(row)) {
      ++number_;
      close();  // when this throws, the next row still goes to the next file
    }
    if (file_ == nullptr) open();
    write(row);
    ++rows_in_file_;
  }

  void finish() override {
    if (file_ != nullptr && std::fflush(file_) != 0) {
      throw Error(current_.string() + ": flush failed: " + std::strerror(errno));
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

  void open() {
    current_ = numbered(path_, number_);
    file_ = std::fopen(current_.c_str(), "w");
    if (file_ == nullptr) {
      throw Error(current_.string() + ": cannot open for writing: " + std::strerror(errno) +
                  " (parameter 'path' must name a file in a writable directory)");
    }
    opened_at_ = Clock::now();
    bytes_in_file_ = 0;
    rows_in_file_ = 0;
    write(std::string(kHeader));
  }

  void close() {
    std::FILE* file = std::exchange(file_, nullptr);
    if (std::fclose(file) != 0) {
      throw Error(current_.string() + ": close failed: " + std::strerror(errno));
    }
  }

  void write(const std::string& text) {
    if (std::fputs(text.c_str(), file_) < 0 || std::fflush(file_) != 0) {
      throw Error(current_.string() + ": write failed: " + std::strerror(errno));
    }
    bytes_in_file_ += text.size();
  }

  const std::filesystem::path path_;
  const std::uint64_t rotate_bytes_;
  const std::chrono::seconds rotate_after_;
  std::uint64_t number_ = 0;
  std::filesystem::path current_;
  std::FILE* file_ = nullptr;
  Clock::time_point opened_at_;
  std::uint64_t bytes_in_file_ = 0;
  std::uint64_t rows_in_file_ = 0;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "sinks.csv";
  d.summary = "one CSV row per frame: ground distance, validity, quality, latency, truth";
  d.inputs = {PortSpec::of<GroundDistance>("distance", "the measurement"),
              PortSpec::of<GroundTruth>("truth", "ground truth, when known").optional()};
  d.params = {
      ParamSpec::path("path", std::nullopt).describe("CSV file to write (replaced)"),
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
