#include "image_folder/image_file.h"

#include <opencv2/imgcodecs.hpp>

#include "image_folder/png_decoder.h"
#include "tilth/error.h"
#include "tilth/regular_file.h"

namespace tilth::recording {

std::string read_image_bytes(const std::filesystem::path& file) {
  std::error_code error;  // a name the file system refuses (too long) is an error, not a throw
  if (!std::filesystem::exists(file, error)) {
    throw Error(file.string() + ": " + (error ? error.message() : "no such file"));
  }
  return read_regular_file(file, kMaxImageBytes, "PNG image");
}

cv::Mat decode_image(const std::string& bytes, const std::filesystem::path& file) {
  if (std::optional<cv::Mat> png = decode_png(bytes, file)) return *std::move(png);
  cv::Mat image;
  if (!bytes.empty()) {
    image = cv::imdecode(
        cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())),
        cv::IMREAD_UNCHANGED);
  }
  if (image.empty()) throw Error(file.string() + ": not a readable image");
  return image;
}

cv::Mat read_image_file(const std::filesystem::path& file) {
  return decode_image(read_image_bytes(file), file);
}

}  // namespace tilth::recording
