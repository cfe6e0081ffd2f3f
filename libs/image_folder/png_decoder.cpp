#include "image_folder/png_decoder.h"

#include <libdeflate.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "image_folder/png_row_filters.h"
#include "tilth/error.h"

namespace tilth::recording {
namespace {

constexpr std::array<std::uint8_t, 8> kSignature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr std::size_t kHeaderBytes = 13;
constexpr std::uint32_t kMaxChunkBytes = 0x7fffffff;  // PNG's limit on a chunk's length
constexpr std::uint32_t kMaxSide = 1u << 24;

enum class ColorType : std::uint8_t { kGrey = 0, kRgb = 2 };

std::uint32_t big_endian_u32(const char* at) {
  const auto* b = reinterpret_cast<const std::uint8_t*>(at);
  return std::uint32_t{b[0]} << 24 | std::uint32_t{b[1]} << 16 | std::uint32_t{b[2]} << 8 | b[3];
}

// A PNG's image header (IHDR), checked.
struct Header {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  int channels = 0;
  int sample_bytes = 0;
  bool rgb = false;
  std::size_t pixel_bytes() const { return static_cast<std::size_t>(channels * sample_bytes); }
  std::size_t row_bytes() const { return width * pixel_bytes(); }
  std::uint64_t filtered_bytes() const { return std::uint64_t{height} * (row_bytes() + 1); }
};

struct Chunk {
  std::string_view type;
  std::string_view data;
  std::size_t offset = 0;  // of its length field in the file
  bool critical() const { return (type[0] & 0x20) == 0; }
};

class PngReader {
 public:
  PngReader(std::string_view bytes, const std::filesystem::path& file)
      : bytes_(bytes), file_(file) {}

  bool is_png() const {
    return bytes_.size() >= kSignature.size() &&
           std::memcmp(bytes_.data(), kSignature.data(), kSignature.size()) == 0;
  }

  // The next chunk, its CRC checked when it is critical (as libpng does, which drops a
  // damaged ancillary chunk and reads on).
  Chunk next_chunk() {
    if (bytes_.size() - position_ < 12) {
      fail("the file ends inside a chunk's header (truncated?)", position_);
    }
    const std::uint32_t length = big_endian_u32(bytes_.data() + position_);
    Chunk chunk{bytes_.substr(position_ + 4, 4), {}, position_};
    for (const char c : chunk.type) {
      if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z')))
        fail("not a chunk type", position_ + 4);
    }
    if (length > kMaxChunkBytes || length > bytes_.size() - position_ - 12) {
      fail("chunk " + std::string(chunk.type) + " of " + std::to_string(length) +
               " bytes goes past the end of the file (truncated?)",
           position_);
    }
    chunk.data = bytes_.substr(position_ + 8, length);
    if (chunk.critical()) {
      const std::uint32_t stored = big_endian_u32(bytes_.data() + position_ + 8 + length);
      const std::uint32_t computed =
          libdeflate_crc32(0, bytes_.data() + position_ + 4, std::size_t{length} + 4);
      if (stored != computed)
        fail("chunk " + std::string(chunk.type) + " fails its CRC", position_);
    }
    position_ += std::size_t{length} + 12;
    return chunk;
  }

  void skip_signature() { position_ = kSignature.size(); }

  [[noreturn]] void fail(const std::string& what, std::size_t at) const {
    throw Error(file_.string() + ": damaged PNG: " + what + " at byte " + std::to_string(at));
  }

 private:
  std::string_view bytes_;
  const std::filesystem::path& file_;
  std::size_t position_ = 0;
};

// The header, or nullopt for a kind this decoder leaves to OpenCV.
std::optional<Header> read_header(const Chunk& chunk, const PngReader& reader) {
  if (chunk.type != "IHDR")
    reader.fail("the first chunk is " + std::string(chunk.type) + ", not IHDR", chunk.offset);
  if (chunk.data.size() != kHeaderBytes) {
    reader.fail("IHDR of " + std::to_string(chunk.data.size()) + " bytes, not 13", chunk.offset);
  }
  Header header;
  header.width = big_endian_u32(chunk.data.data());
  header.height = big_endian_u32(chunk.data.data() + 4);
  const auto bit_depth = static_cast<std::uint8_t>(chunk.data[8]);
  const auto color_type = static_cast<std::uint8_t>(chunk.data[9]);
  if (header.width == 0 || header.height == 0) reader.fail("an image of 0 pixels", chunk.offset);
  if (chunk.data[10] != 0 || chunk.data[11] != 0) {
    reader.fail("compression or filter method other than 0", chunk.offset);
  }
  const bool known_kind = (color_type == static_cast<std::uint8_t>(ColorType::kGrey) ||
                           color_type == static_cast<std::uint8_t>(ColorType::kRgb)) &&
                          (bit_depth == 8 || bit_depth == 16) && chunk.data[12] == 0;
  if (!known_kind) return std::nullopt;
  if (header.width > kMaxSide || header.height > kMaxSide) {
    reader.fail("an image of " + std::to_string(header.width) + "x" +
                    std::to_string(header.height) + " pixels",
                chunk.offset);
  }
  header.rgb = color_type == static_cast<std::uint8_t>(ColorType::kRgb);
  header.channels = header.rgb ? 3 : 1;
  header.sample_bytes = bit_depth / 8;
  if (header.filtered_bytes() > kMaxPngPixelBytes) {
    reader.fail("an image of " + std::to_string(header.width) + "x" +
                    std::to_string(header.height) + " pixels, larger than the " +
                    std::to_string(kMaxPngPixelBytes >> 20) + " MiB a recording's image may be",
                chunk.offset);
  }
  return header;
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// The image's filtered rows: its IDAT chunks' zlib stream inflated.
std::unique_ptr<std::uint8_t[]> inflate_rows(std::string_view stream, std::size_t first_idat,
                                             const Header& header, const PngReader& reader) {
  const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> decompressor(
      libdeflate_alloc_decompressor());
  if (!decompressor) throw std::bad_alloc();
  const std::size_t expected = header.filtered_bytes();
  std::unique_ptr<std::uint8_t[]> rows(new std::uint8_t[expected]);
  std::size_t inflated = 0;
  const libdeflate_result result = libdeflate_zlib_decompress(
      decompressor.get(), stream.data(), stream.size(), rows.get(), expected, &inflated);
  if (result == LIBDEFLATE_INSUFFICIENT_SPACE) {
    reader.fail("IDAT holds more than the " + std::to_string(expected) + " bytes IHDR's size gives",
                first_idat);
  }
  if (result != LIBDEFLATE_SUCCESS) {
    reader.fail("IDAT's zlib stream is damaged (inflating or its Adler-32 failed)", first_idat);
  }
  if (inflated != expected) {
    reader.fail("IDAT holds " + std::to_string(inflated) + " bytes of rows, IHDR's size gives " +
                    std::to_string(expected),
                first_idat);
  }
  return rows;
}

// Row `y` of the image, from its unfiltered bytes, in OpenCV's order (BGR, host-order
// 16-bit samples).
void store_row(const std::uint8_t* unfiltered, const Header& header, cv::Mat& image, int y) {
  auto* out = image.ptr<std::uint8_t>(y);
  const std::size_t samples = std::size_t{header.width} * header.channels;
  if (header.sample_bytes == 1) {
    if (!header.rgb) {
      std::memcpy(out, unfiltered, samples);
      return;
    }
    for (std::size_t i = 0; i < samples; i += 3) {
      out[i] = unfiltered[i + 2];
      out[i + 1] = unfiltered[i + 1];
      out[i + 2] = unfiltered[i];
    }
    return;
  }
  auto* out16 = reinterpret_cast<std::uint16_t*>(out);
  const auto sample = [unfiltered](std::size_t i) {
    return static_cast<std::uint16_t>(unfiltered[2 * i] << 8 | unfiltered[2 * i + 1]);
  };
  if (!header.rgb) {
    for (std::size_t i = 0; i < samples; ++i) out16[i] = sample(i);
    return;
  }
  for (std::size_t i = 0; i < samples; i += 3) {
    out16[i] = sample(i + 2);
    out16[i + 1] = sample(i + 1);
    out16[i + 2] = sample(i);
  }
}

}  // namespace

std::optional<cv::Mat> decode_png(std::string_view bytes, const std::filesystem::path& file) {
  PngReader reader(bytes, file);
  if (!reader.is_png()) return std::nullopt;
  reader.skip_signature();
  const Chunk first = reader.next_chunk();
  const std::optional<Header> header = read_header(first, reader);
  if (!header) return std::nullopt;

  std::vector<std::string_view> idat;
  std::size_t first_idat = 0;
  for (bool idat_ended = false;;) {
    const Chunk chunk = reader.next_chunk();
    if (chunk.type == "IEND") break;
    if (chunk.type == "IDAT") {
      if (idat_ended) reader.fail("IDAT chunks that do not follow each other", chunk.offset);
      if (idat.empty()) first_idat = chunk.offset;
      idat.push_back(chunk.data);
      continue;
    }
    idat_ended = !idat.empty();
    if (chunk.type == "tRNS") return std::nullopt;  // OpenCV decodes it with alpha
    if (chunk.type == "IHDR") reader.fail("a second IHDR", chunk.offset);
    if (chunk.critical() && chunk.type != "PLTE") {
      reader.fail("unknown critical chunk " + std::string(chunk.type), chunk.offset);
    }
  }
  if (idat.empty()) reader.fail("no IDAT chunk before IEND", kSignature.size());

  std::string joined;
  std::string_view stream = idat.front();
  if (idat.size() > 1) {
    std::size_t total = 0;
    for (const std::string_view part : idat) total += part.size();
    joined.reserve(total);
    for (const std::string_view part : idat) joined.append(part);
    stream = joined;
  }
  const std::unique_ptr<std::uint8_t[]> rows = inflate_rows(stream, first_idat, *header, reader);

  cv::Mat image(static_cast<int>(header->height), static_cast<int>(header->width),
                CV_MAKETYPE(header->sample_bytes == 1 ? CV_8U : CV_16U, header->channels));
  const std::size_t row_bytes = header->row_bytes();
  const std::vector<std::uint8_t> zeros(row_bytes, 0);
  const std::uint8_t* above = zeros.data();
  for (int y = 0; y < image.rows; ++y) {
    std::uint8_t* filtered = rows.get() + static_cast<std::size_t>(y) * (row_bytes + 1);
    const std::uint8_t filter = filtered[0];
    if (filter >= kPngFilterCount) {
      reader.fail("row " + std::to_string(y) + " has filter type " + std::to_string(filter) +
                      " (PNG has 0 to 4)",
                  first_idat);
    }
    unfilter_png_row(static_cast<PngFilter>(filter), filtered + 1, above, row_bytes,
                     header->pixel_bytes());
    store_row(filtered + 1, *header, image, y);
    above = filtered + 1;
  }
  return image;
}

}  // namespace tilth::recording
