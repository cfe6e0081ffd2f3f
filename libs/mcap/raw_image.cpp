// CDR as ROS 2 writes it (XCDR1, little-endian): a 4-byte encapsulation header, then
// each field aligned to its own size counted from the end of the header; a string is a
// uint32 length that includes a terminating NUL, then the bytes and the NUL; uint8[] is a
// uint32 count, then the bytes.
#include "mcap/raw_image.h"

#include <bit>
#include <cstring>
#include <limits>
#include <optional>

#include "tilth/error.h"

namespace tilth::mcap {
namespace {

static_assert(std::endian::native == std::endian::little, "CDR is written little-endian");

constexpr std::string_view kLittleEndianCdr("\x00\x01\x00\x00", 4);
constexpr std::size_t kHeaderSize = kLittleEndianCdr.size();
constexpr std::int64_t kNsPerSecond = 1'000'000'000;

class CdrWriter {
 public:
  explicit CdrWriter(std::size_t reserve) {
    out_.reserve(reserve);
    out_ += kLittleEndianCdr;
  }
  void u32(std::uint32_t value) { put(value); }
  void i32(std::int32_t value) { put(value); }
  void string(std::string_view text) {
    u32(static_cast<std::uint32_t>(text.size() + 1));
    out_ += text;
    out_ += '\0';
  }
  void bytes(std::string_view data) {
    u32(static_cast<std::uint32_t>(data.size()));
    out_ += data;
  }
  std::string take() { return std::move(out_); }

 private:
  template <class T>
  void put(T value) {
    out_.append((sizeof(T) - (out_.size() - kHeaderSize) % sizeof(T)) % sizeof(T), '\0');
    out_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  std::string out_;
};

class CdrReader {
 public:
  CdrReader(std::string_view data, const std::string& where) : data_(data), where_(where) {
    if (data_.substr(0, kHeaderSize) != kLittleEndianCdr) {
      throw Error(where_ + ": expected a little-endian CDR message (header 00 01 00 00)");
    }
    position_ = kHeaderSize;
  }
  std::uint32_t u32(std::string_view field) { return get<std::uint32_t>(field); }
  std::int32_t i32(std::string_view field) { return get<std::int32_t>(field); }
  std::string string(std::string_view field) {
    const std::uint32_t size = u32(field);
    const std::string_view text = take(size, field);
    if (size == 0 || text.back() != '\0') {
      throw Error(where_ + ": " + std::string(field) + ": expected a NUL-terminated string");
    }
    return std::string(text.substr(0, size - 1));
  }
  std::string_view bytes(std::string_view field) { return take(u32(field), field); }

 private:
  template <class T>
  T get(std::string_view field) {
    position_ += (sizeof(T) - (position_ - kHeaderSize) % sizeof(T)) % sizeof(T);
    T value{};
    std::memcpy(&value, take(sizeof(T), field).data(), sizeof(T));
    return value;
  }
  std::string_view take(std::size_t size, std::string_view field) {
    if (size > data_.size() - std::min(position_, data_.size())) {
      throw Error(where_ + ": " + std::string(field) + ": " + std::to_string(size) +
                  " bytes at offset " + std::to_string(position_) + " run past the message's " +
                  std::to_string(data_.size()) + " bytes");
    }
    const std::string_view bytes = data_.substr(position_, size);
    position_ += size;
    return bytes;
  }

  std::string_view data_;
  const std::string& where_;
  std::size_t position_ = 0;
};

// OpenCV type and bytes per pixel of a Foxglove encoding Tilth records.
std::optional<std::pair<int, int>> pixel_type(std::string_view encoding) {
  if (encoding == "mono16") return std::pair{CV_16UC1, 2};
  if (encoding == "bgr8" || encoding == "rgb8") return std::pair{CV_8UC3, 3};
  if (encoding == "mono8" || encoding.starts_with("bayer_")) return std::pair{CV_8UC1, 1};
  return std::nullopt;
}

}  // namespace

std::string raw_image_schema() {
  return "# foxglove_msgs/msg/RawImage: a raw image (https://docs.foxglove.dev)\n"
         "builtin_interfaces/Time timestamp\n"
         "string frame_id\n"
         "uint32 width\n"
         "uint32 height\n"
         "string encoding\n"
         "uint32 step\n"
         "uint8[] data\n"
         "================================================================================\n"
         "MSG: builtin_interfaces/Time\n"
         "int32 sec\n"
         "uint32 nanosec\n";
}

std::string encode_raw_image(const cv::Mat& image, std::string_view encoding,
                             std::int64_t timestamp_ns, std::string_view frame_id) {
  const cv::Mat pixels = image.isContinuous() ? image : image.clone();
  const std::size_t step = pixels.cols * pixels.elemSize();
  const std::string_view data(reinterpret_cast<const char*>(pixels.data), step * pixels.rows);
  if (timestamp_ns < 0 || timestamp_ns / kNsPerSecond > std::numeric_limits<std::int32_t>::max()) {
    throw Error("timestamp " + std::to_string(timestamp_ns) +
                " ns: expected 0 to 2^31 s (a ROS 2 time has int32 seconds)");
  }
  CdrWriter cdr(data.size() + 64 + frame_id.size() + encoding.size());
  cdr.i32(static_cast<std::int32_t>(timestamp_ns / kNsPerSecond));
  cdr.u32(static_cast<std::uint32_t>(timestamp_ns % kNsPerSecond));
  cdr.string(frame_id);
  cdr.u32(static_cast<std::uint32_t>(pixels.cols));
  cdr.u32(static_cast<std::uint32_t>(pixels.rows));
  cdr.string(encoding);
  cdr.u32(static_cast<std::uint32_t>(step));
  cdr.bytes(data);
  return cdr.take();
}

RawImage decode_raw_image(std::string_view message, const std::string& where) {
  CdrReader cdr(message, where);
  RawImage image;
  const std::int32_t sec = cdr.i32("timestamp.sec");
  const std::uint32_t nanosec = cdr.u32("timestamp.nanosec");
  if (sec < 0 || nanosec >= kNsPerSecond) {
    throw Error(where + ": timestamp: expected sec >= 0 and nanosec in [0, 999999999], got " +
                std::to_string(sec) + " and " + std::to_string(nanosec));
  }
  image.timestamp_ns = sec * kNsPerSecond + nanosec;
  image.frame_id = cdr.string("frame_id");
  const std::uint32_t width = cdr.u32("width");
  const std::uint32_t height = cdr.u32("height");
  image.encoding = cdr.string("encoding");
  const std::uint32_t step = cdr.u32("step");
  const std::string_view data = cdr.bytes("data");
  const auto type = pixel_type(image.encoding);
  if (!type) {
    throw Error(where + ": encoding: '" + image.encoding +
                "' is not recorded by Tilth; expected mono16, mono8, bgr8, rgb8 or bayer_*8");
  }
  if (width == 0 || height == 0 || width > 65535 || height > 65535 ||
      step < static_cast<std::size_t>(width) * type->second ||
      data.size() != static_cast<std::size_t>(step) * height) {
    throw Error(where + ": expected " + std::to_string(height) + " rows of step " +
                std::to_string(step) + " >= width " + std::to_string(width) + " x " +
                std::to_string(type->second) + " bytes, got " + std::to_string(data.size()) +
                " data bytes");
  }
  const cv::Mat wrapped(static_cast<int>(height), static_cast<int>(width), type->first,
                        const_cast<char*>(data.data()), step);
  image.pixels = wrapped.clone();
  return image;
}

}  // namespace tilth::mcap
