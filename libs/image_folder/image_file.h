// An image file of a recording (a frame's PNG, or a mask to import into one), read safely:
// a regular file only, within a size limit, decoded unchanged as OpenCV decodes it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core/mat.hpp>

namespace tilth::recording {

// A PNG of the largest image a rig gives (16-bit 1280x1024x3: 7.5 MiB raw) with room
// for PNG's worst case; a larger file is not a frame of a recording.
inline constexpr std::uint64_t kMaxImageBytes = 256 << 20;

// The file's bytes. Throws tilth::Error "FILE: no such file", the file system's reason
// ("File name too long"), or read_regular_file's message (not a regular file, larger than
// kMaxImageBytes).
std::string read_image_bytes(const std::filesystem::path& file);

// `bytes` decoded unchanged: a recording's kinds of PNG by decode_png, others by OpenCV
// (a palette PNG comes out as BGR). Throws decode_png's "FILE: damaged PNG: ..." or
// tilth::Error "FILE: not a readable image" when OpenCV cannot decode them.
cv::Mat decode_image(const std::string& bytes, const std::filesystem::path& file);

// read_image_bytes, then decode_image.
cv::Mat read_image_file(const std::filesystem::path& file);

}  // namespace tilth::recording
