// The calibration views of `tilth calibrate solve`: pairs of a ToF intensity image and a
// colour image of the same board pose, found by name in folders, and the board's inner
// corners found in each image.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

#include "tilth/messages/color_image.h"

namespace tilth::calibrate {

// Where a view's two images are: FOLDER/NAME_intensity.png and FOLDER/NAME_color.png.
struct ViewFiles {
  std::string name;  // FOLDER/NAME, as messages and the report name the view
  std::filesystem::path intensity;
  std::filesystem::path color;
};

// Every pair in each folder, sorted by name. Throws tilth::Error for a path that is not a
// folder, a folder without pairs, and an image whose partner is missing.
std::vector<ViewFiles> find_views(const std::vector<std::filesystem::path>& folders);

// How the colour camera's 1-channel images are to be read: as grey (nullopt), or as a
// Bayer mosaic named by its first row's first two pixels, as `--color-bayer` names it:
// "RG" (GenICam's BayerRG8: R G / G B) -> PixelFormat::kBayerRggb8. Throws tilth::Error
// for another text.
std::optional<PixelFormat> parse_color_mosaic(const std::string& text);

// kThorough: an exhaustive search (the solve; a second or two for a 1280x1024 image);
// kQuick: none (live capture; about 50 ms for 640x512), which misses more boards. Both
// refine the corners to a tenth of a pixel or better.
enum class BoardSearch { kThorough, kQuick };

// The board's `inner_corners` (columns x rows) in an 8-bit grey image, row by row from the
// end nearer the image's top left (cv::findChessboardCornersSB); empty when the board is
// not found or the corners found do not form a smooth grid (a misdetection).
std::vector<cv::Point2f> board_corners(const cv::Mat& gray, cv::Size inner_corners,
                                       BoardSearch search);

struct BoardView {
  std::string name;
  cv::Size depth_size;
  cv::Size color_size;
  std::vector<cv::Point2f> depth_corners;  // empty when the board was not found
  std::vector<cv::Point2f> color_corners;
};

// The images read and the board's `inner_corners` (columns x rows) found in each. Throws
// tilth::Error naming the file when an image cannot be read or has the wrong type (the
// intensity: 1 channel, 8 or 16 bits; the colour: 8 bits, 1 channel or 3 (BGR)).
BoardView find_board(const ViewFiles& files, cv::Size inner_corners,
                     std::optional<PixelFormat> mosaic);

// find_board of every view, on all cores (a second or two per colour image); throws the
// error of the first view that has one.
std::vector<BoardView> find_boards(const std::vector<ViewFiles>& views, cv::Size inner_corners,
                                   std::optional<PixelFormat> mosaic);

// The ToF intensity scaled to 8 bits: its 1st percentile to 0 and its 99th to 255, so
// the board's contrast fills the range whatever the exposure.
cv::Mat intensity_to_8bit(const cv::Mat& intensity);

}  // namespace tilth::calibrate
