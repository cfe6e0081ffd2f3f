// libs/image_folder's PNG decoder: the same pixels as OpenCV on what OpenCV writes and
// on PNGs built here byte by byte (every row filter, split and ancillary chunks), the
// kinds it leaves to OpenCV, and damage named with the byte where it is.
#include <zlib.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "image_folder/image_file.h"
#include "image_folder/png_decoder.h"
#include "tilth/error.h"

namespace tilth::recording {
namespace {

const std::filesystem::path kFile = "rec/color/000007.png";

std::string big_endian(std::uint32_t value) {
  return {static_cast<char>(value >> 24), static_cast<char>(value >> 16),
          static_cast<char>(value >> 8), static_cast<char>(value)};
}

// A chunk as PNG's specification lays it out, its CRC from zlib.
std::string chunk(const std::string& type, const std::string& data) {
  std::string typed = type + data;
  const auto crc = static_cast<std::uint32_t>(
      crc32(0, reinterpret_cast<const Bytef*>(typed.data()), static_cast<uInt>(typed.size())));
  return big_endian(static_cast<std::uint32_t>(data.size())) + typed + big_endian(crc);
}

std::string header_data(std::uint32_t width, std::uint32_t height, int bit_depth, int color_type,
                        int interlace = 0) {
  return big_endian(width) + big_endian(height) +
         std::string{static_cast<char>(bit_depth), static_cast<char>(color_type), 0, 0,
                     static_cast<char>(interlace)};
}

int paeth(int left, int up, int up_left) {
  const int p = left + up - up_left;
  const int a = std::abs(p - left), b = std::abs(p - up), c = std::abs(p - up_left);
  return a <= b && a <= c ? left : (b <= c ? up : up_left);
}

// `image`'s rows as a PNG stores them, big-endian samples in RGB order, row y filtered
// with filters[y % filters.size()], before compression.
std::string filtered_rows(const cv::Mat& image, const std::vector<int>& filters) {
  const int sample_bytes = static_cast<int>(image.elemSize1());
  const int pixel_bytes = static_cast<int>(image.elemSize());
  const int row_bytes = image.cols * pixel_bytes;
  std::vector<std::uint8_t> above(row_bytes, 0), row(row_bytes);
  std::string out;
  for (int y = 0; y < image.rows; ++y) {
    const auto* pixels = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      for (int c = 0; c < image.channels(); ++c) {
        const int from_channel = image.channels() == 3 ? 2 - c : c;
        for (int b = 0; b < sample_bytes; ++b) {
          const int host_byte = sample_bytes == 2 ? 1 - b : b;
          row[x * pixel_bytes + c * sample_bytes + b] =
              pixels[x * pixel_bytes + from_channel * sample_bytes + host_byte];
        }
      }
    }
    const int filter = filters[y % filters.size()];
    out += static_cast<char>(filter);
    for (int i = 0; i < row_bytes; ++i) {
      const int left = i >= pixel_bytes ? row[i - pixel_bytes] : 0;
      const int up_left = i >= pixel_bytes ? above[i - pixel_bytes] : 0;
      const int predictors[] = {0, left, above[i], (left + above[i]) / 2,
                                paeth(left, above[i], up_left)};
      out += static_cast<char>(row[i] - predictors[filter]);
    }
    above = row;
  }
  return out;
}

std::string zlib_stream(const std::string& data) {
  uLongf size = compressBound(static_cast<uLong>(data.size()));
  std::string out(size, '\0');
  EXPECT_EQ(
      compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                reinterpret_cast<const Bytef*>(data.data()), static_cast<uLong>(data.size()), 6),
      Z_OK);
  out.resize(size);
  return out;
}

const std::string kSignature{"\x89PNG\r\n\x1a\n", 8};

// A PNG of `image` built without libpng: its rows filtered as given, the stream split into
// IDAT chunks of `idat_bytes`, `before_idat` and `after_idat` chunks around them.
std::string build_png(const cv::Mat& image, const std::vector<int>& filters,
                      std::size_t idat_bytes = 1 << 20, const std::string& before_idat = "",
                      const std::string& after_idat = "") {
  const int color_type = image.channels() == 3 ? 2 : 0;
  std::string png =
      kSignature +
      chunk("IHDR", header_data(image.cols, image.rows, static_cast<int>(8 * image.elemSize1()),
                                color_type)) +
      before_idat;
  const std::string stream = zlib_stream(filtered_rows(image, filters));
  for (std::size_t at = 0; at < stream.size(); at += idat_bytes) {
    png += chunk("IDAT", stream.substr(at, idat_bytes));
  }
  return png + after_idat + chunk("IEND", "");
}

cv::Mat random_image(int rows, int cols, int type, unsigned seed) {
  cv::Mat image(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

// A smooth ramp with noise: filters and compression behave as on camera images.
cv::Mat camera_like_image(int rows, int cols, int type, unsigned seed) {
  cv::Mat ramp(rows, cols, CV_MAKETYPE(CV_32F, CV_MAT_CN(type)));
  const double scale = CV_MAT_DEPTH(type) == CV_16U ? 60000.0 : 230.0;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      auto* p = ramp.ptr<float>(y) + x * ramp.channels();
      for (int c = 0; c < ramp.channels(); ++c) {
        p[c] = static_cast<float>(scale * (x + 2 * y + 7 * c) / (cols + 2 * rows + 14));
      }
    }
  }
  cv::Mat noise(rows, cols, ramp.type());
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0, scale / 100);
  cv::Mat image;
  cv::Mat(ramp + noise).convertTo(image, type);
  return image;
}

std::string encode(const cv::Mat& image, const std::vector<int>& params = {}) {
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes, params));
  return {bytes.begin(), bytes.end()};
}

cv::Mat opencv_decoded(const std::string& bytes) {
  return cv::imdecode(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())),
      cv::IMREAD_UNCHANGED);
}

void expect_same_pixels(const cv::Mat& decoded, const cv::Mat& expected) {
  ASSERT_EQ(decoded.type(), expected.type());
  ASSERT_EQ(decoded.size(), expected.size());
  EXPECT_EQ(cv::norm(decoded, expected, cv::NORM_INF), 0.0);
}

std::string damage_message(const std::string& bytes) {
  try {
    decode_png(bytes, kFile);
  } catch (const Error& e) {
    return e.what();
  }
  return "decoded";
}

const std::array<int, 4> kKinds{CV_8UC1, CV_16UC1, CV_8UC3, CV_16UC3};

TEST(DecodePng, DecodesWhatOpenCvWritesAsOpenCvDoes) {
  const std::vector<cv::Size> sizes{{1, 1}, {7, 3}, {33, 17}, {640, 480}};
  const std::vector<std::vector<int>> settings{
      {},
      {cv::IMWRITE_PNG_COMPRESSION, 0},
      {cv::IMWRITE_PNG_COMPRESSION, 9},
      {cv::IMWRITE_PNG_STRATEGY, cv::IMWRITE_PNG_STRATEGY_FILTERED},
      {cv::IMWRITE_PNG_STRATEGY, cv::IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY}};
  unsigned seed = 1;
  for (const int kind : kKinds) {
    for (const cv::Size size : sizes) {
      for (const auto& params : settings) {
        SCOPED_TRACE(cv::typeToString(kind) + " " + std::to_string(size.width) + "x" +
                     std::to_string(size.height) + " setting " +
                     std::to_string(&params - settings.data()));
        const cv::Mat image = camera_like_image(size.height, size.width, kind, ++seed);
        const std::string bytes = encode(image, params);
        const std::optional<cv::Mat> decoded = decode_png(bytes, kFile);
        ASSERT_TRUE(decoded.has_value());
        expect_same_pixels(*decoded, image);
        expect_same_pixels(*decoded, opencv_decoded(bytes));
      }
    }
  }
}

TEST(DecodePng, UndoesEveryRowFilter) {
  const std::vector<std::vector<int>> filter_sets{{0}, {1}, {2}, {3}, {4}, {4, 0, 3, 1, 2}};
  unsigned seed = 100;
  for (const int kind : kKinds) {
    for (const auto& filters : filter_sets) {
      SCOPED_TRACE(cv::typeToString(kind) + " first filter " + std::to_string(filters[0]) + " of " +
                   std::to_string(filters.size()));
      // Random samples reach every wrap-around of the byte arithmetic.
      const cv::Mat image = random_image(13, 21, kind, ++seed);
      const std::string bytes = build_png(image, filters);
      const std::optional<cv::Mat> decoded = decode_png(bytes, kFile);
      ASSERT_TRUE(decoded.has_value());
      expect_same_pixels(*decoded, image);
      expect_same_pixels(*decoded, opencv_decoded(bytes));
    }
  }
}

TEST(DecodePng, ReadsSplitDataAndSkipsAncillaryChunks) {
  const cv::Mat image = random_image(9, 11, CV_8UC3, 7);
  const std::string text = chunk("tEXt", std::string("Software\0test", 13));
  const std::string palette = chunk("PLTE", std::string(6, '\x10'));  // a suggestion, in RGB
  const std::string bytes = build_png(image, {1, 4}, 7, text + palette, text);
  const std::optional<cv::Mat> decoded = decode_png(bytes, kFile);
  ASSERT_TRUE(decoded.has_value());
  expect_same_pixels(*decoded, image);

  // libpng drops an ancillary chunk whose CRC fails and reads on; so does the decoder.
  std::string damaged_text = bytes;
  damaged_text[kSignature.size() + 25 + 8] ^= 1;  // the first tEXt's keyword
  const std::optional<cv::Mat> read_on = decode_png(damaged_text, kFile);
  ASSERT_TRUE(read_on.has_value());
  expect_same_pixels(*read_on, image);
}

TEST(DecodePng, LeavesOtherKindsToOpenCv) {
  const cv::Mat grey = random_image(5, 6, CV_8UC1, 3);
  const std::string grey_stream = zlib_stream(filtered_rows(grey, {0}));
  const std::vector<std::pair<std::string, std::string>> others{
      {"BGRA", encode(random_image(5, 6, CV_8UC4, 4))},
      {"1-bit grey", encode(grey > 128, {cv::IMWRITE_PNG_BILEVEL, 1})},
      {"interlaced", kSignature + chunk("IHDR", header_data(6, 5, 8, 0, 1)) +
                         chunk("IDAT", grey_stream) + chunk("IEND", "")},
      {"transparency", build_png(grey, {0}, 1 << 20, chunk("tRNS", std::string(2, '\0')))},
      {"not a PNG", "GIF89a"}};
  for (const auto& [kind, bytes] : others) {
    SCOPED_TRACE(kind);
    EXPECT_FALSE(decode_png(bytes, kFile).has_value());
  }
  // decode_image hands them to OpenCV.
  const std::string bgra = others[0].second;
  expect_same_pixels(decode_image(bgra, kFile), opencv_decoded(bgra));
  const std::string transparent = others[3].second;
  expect_same_pixels(decode_image(transparent, kFile), opencv_decoded(transparent));
}

// The byte offsets below: the signature is 8 bytes, IHDR's chunk 25, so IDAT starts at 33.
TEST(DecodePng, NamesTheDamageAndWhereItIs) {
  const cv::Mat image = random_image(4, 5, CV_16UC1, 9);
  const std::string good = build_png(image, {1});
  const std::string rows = filtered_rows(image, {1});
  const auto with_header = [&](const std::string& header, const std::string& data) {
    return kSignature + chunk("IHDR", header) + chunk("IDAT", zlib_stream(data)) +
           chunk("IEND", "");
  };
  const std::string prefix = "rec/color/000007.png: damaged PNG: ";

  EXPECT_EQ(damage_message(good.substr(0, good.size() - 6)),
            prefix + "the file ends inside a chunk's header (truncated?) at byte " +
                std::to_string(good.size() - 12));
  EXPECT_EQ(damage_message(good.substr(0, 33 + 12 + 3)),
            prefix + "chunk IDAT of " + std::to_string(zlib_stream(rows).size()) +
                " bytes goes past the end of the file (truncated?) at byte 33");

  std::string flipped = good;
  flipped[33 + 8 + 3] ^= 0x40;
  EXPECT_EQ(damage_message(flipped), prefix + "chunk IDAT fails its CRC at byte 33");

  std::string stream = zlib_stream(rows);
  stream[stream.size() - 1] ^= 1;  // the Adler-32, CRC made again
  EXPECT_EQ(damage_message(kSignature + chunk("IHDR", header_data(5, 4, 16, 0)) +
                           chunk("IDAT", stream) + chunk("IEND", "")),
            prefix + "IDAT's zlib stream is damaged (inflating or its Adler-32 failed) at byte 33");

  EXPECT_EQ(damage_message(with_header(header_data(5, 5, 16, 0), rows)),
            prefix + "IDAT holds 44 bytes of rows, IHDR's size gives 55 at byte 33");
  EXPECT_EQ(damage_message(with_header(header_data(5, 3, 16, 0), rows)),
            prefix + "IDAT holds more than the 33 bytes IHDR's size gives at byte 33");

  std::string bad_filter = rows;
  bad_filter[2 * 11] = 5;
  EXPECT_EQ(damage_message(with_header(header_data(5, 4, 16, 0), bad_filter)),
            prefix + "row 2 has filter type 5 (PNG has 0 to 4) at byte 33");

  EXPECT_EQ(damage_message(with_header(header_data(0, 4, 16, 0), rows)),
            prefix + "an image of 0 pixels at byte 8");
  EXPECT_EQ(damage_message(with_header(header_data(100000, 100000, 16, 0), rows)),
            prefix +
                "an image of 100000x100000 pixels, larger than the 1024 MiB a recording's "
                "image may be at byte 8");
  EXPECT_EQ(damage_message(kSignature + chunk("IDAT", zlib_stream(rows))),
            prefix + "the first chunk is IDAT, not IHDR at byte 8");

  const std::string ihdr = chunk("IHDR", header_data(5, 4, 16, 0));
  const std::string idat = chunk("IDAT", zlib_stream(rows));
  EXPECT_EQ(damage_message(kSignature + ihdr + chunk("ABCD", "x") + idat + chunk("IEND", "")),
            prefix + "unknown critical chunk ABCD at byte 33");
  EXPECT_EQ(damage_message(kSignature + ihdr + chunk("IEND", "")),
            prefix + "no IDAT chunk before IEND at byte 8");
  const std::string half = zlib_stream(rows);
  EXPECT_EQ(
      damage_message(kSignature + ihdr + chunk("IDAT", half.substr(0, 10)) + chunk("tEXt", "a") +
                     chunk("IDAT", half.substr(10)) + chunk("IEND", "")),
      prefix + "IDAT chunks that do not follow each other at byte " + std::to_string(33 + 22 + 13));

  // decode_image passes the damage on rather than OpenCV's "not a readable image".
  try {
    decode_image(flipped, kFile);
    FAIL() << "decoded a PNG whose IDAT fails its CRC";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), prefix + "chunk IDAT fails its CRC at byte 33");
  }
}

}  // namespace
}  // namespace tilth::recording
