// PNG files of the kinds a recording holds (8- or 16-bit grey or RGB, not interlaced),
// decoded with libdeflate: PNG decoding with zlib bound a replay, and libdeflate inflates
// the same data in about half the time, checksums included.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>

#include <opencv2/core/mat.hpp>

namespace tilth::recording {

// Decoded images larger than this are not frames of a recording (the largest a rig gives
// is 7.5 MiB), and a damaged header must not make the reader allocate what it says.
inline constexpr std::uint64_t kMaxPngPixelBytes = std::uint64_t{1} << 30;

// `bytes` as OpenCV's imdecode with IMREAD_UNCHANGED decodes them (grey as 1 channel,
// RGB as BGR, 16-bit samples in the host's byte order), or nullopt when they are not a
// PNG of those kinds (a palette, alpha or transparency, interlacing, fewer than 8 bits).
// Throws tilth::Error "FILE: damaged PNG: <what> at byte N" when its chunks, checksums
// or compressed data are not what PNG's specification expects.
std::optional<cv::Mat> decode_png(std::string_view bytes, const std::filesystem::path& file);

}  // namespace tilth::recording
