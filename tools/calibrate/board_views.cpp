#include "board_views.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "color/color_conversion.h"
#include "tilth/error.h"

namespace tilth::calibrate {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kIntensitySuffix = "_intensity.png";
constexpr std::string_view kColorSuffix = "_color.png";

cv::Mat read_image(const fs::path& file) {
  cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) throw Error(file.string() + ": cannot read it as an image (expected a PNG)");
  return image;
}

cv::Mat color_to_gray(const cv::Mat& color, std::optional<PixelFormat> mosaic,
                      const fs::path& file) {
  if (color.depth() != CV_8U || (color.channels() != 1 && color.channels() != 3)) {
    throw Error(file.string() +
                ": expected an 8-bit colour image (1 channel: Bayer or grey; 3: BGR)");
  }
  if (color.channels() == 3 && mosaic) {
    throw Error(file.string() + ": has 3 channels, but --color-bayer says it is a Bayer mosaic");
  }
  const PixelFormat format =
      color.channels() == 3 ? PixelFormat::kBgr8 : mosaic.value_or(PixelFormat::kMono8);
  cv::Mat gray;
  color::to_gray(color, format, gray);
  return gray;
}

// Whether the corners form a smooth grid: each one near the middle of its neighbours
// along a row and down a column. Perspective and lens distortion bend the grid by a few
// percent of a square; the detector, rarely, returns a row of corners elsewhere (seen on
// rendered views, not every run), which would drag the whole solve.
bool regular_grid(const std::vector<cv::Point2f>& corners, cv::Size inner_corners) {
  constexpr double kMaxBend = 0.2;  // of the neighbours' distance
  const auto at = [&](int col, int row) { return corners[row * inner_corners.width + col]; };
  for (int row = 0; row < inner_corners.height; ++row) {
    for (int col = 0; col < inner_corners.width; ++col) {
      for (const auto& [dc, dr] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (col - dc < 0 || row - dr < 0 || col + dc >= inner_corners.width ||
            row + dr >= inner_corners.height) {
          continue;
        }
        const cv::Point2f before = at(col - dc, row - dr);
        const cv::Point2f after = at(col + dc, row + dr);
        const cv::Point2f bend = before + after - 2.0f * at(col, row);
        if (cv::norm(bend) > kMaxBend * cv::norm(after - before)) return false;
      }
    }
  }
  return true;
}

// The smallest distance between neighbouring corners, in pixels.
float corner_spacing(const std::vector<cv::Point2f>& corners, cv::Size inner_corners) {
  float spacing = std::numeric_limits<float>::max();
  for (int i = 0; i < static_cast<int>(corners.size()); ++i) {
    if ((i + 1) % inner_corners.width != 0) {
      spacing = std::min(spacing, static_cast<float>(cv::norm(corners[i + 1] - corners[i])));
    }
    if (i + inner_corners.width < static_cast<int>(corners.size())) {
      spacing = std::min(
          spacing, static_cast<float>(cv::norm(corners[i + inner_corners.width] - corners[i])));
    }
  }
  return spacing;
}

}  // namespace

std::vector<ViewFiles> find_views(const std::vector<fs::path>& folders) {
  std::vector<ViewFiles> views;
  for (const auto& folder : folders) {
    if (!fs::is_directory(folder)) {
      throw Error(folder.string() + ": not a folder; expected one holding NAME" +
                  std::string(kIntensitySuffix) + " and NAME" + std::string(kColorSuffix) +
                  " pairs");
    }
    std::vector<ViewFiles> found;
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string file = entry.path().filename().string();
      const bool intensity = file.ends_with(kIntensitySuffix);
      const bool color = file.ends_with(kColorSuffix);
      if (!intensity && !color) continue;
      const std::string name =
          file.substr(0, file.size() - (intensity ? kIntensitySuffix : kColorSuffix).size());
      const fs::path partner =
          folder / (name + std::string(intensity ? kColorSuffix : kIntensitySuffix));
      if (!fs::exists(partner)) {
        throw Error(entry.path().string() + ": its partner " + partner.string() +
                    " is missing; a view is a pair of images of one board pose");
      }
      if (intensity) {
        found.push_back({(folder / name).string(), entry.path(), partner});
      }
    }
    if (found.empty()) {
      throw Error(folder.string() + ": holds no view; expected NAME" +
                  std::string(kIntensitySuffix) + " and NAME" + std::string(kColorSuffix) +
                  " pairs");
    }
    std::sort(found.begin(), found.end(),
              [](const ViewFiles& a, const ViewFiles& b) { return a.name < b.name; });
    views.insert(views.end(), found.begin(), found.end());
  }
  return views;
}

// cv::cornerSubPix refines the detector's corners in a window of 0.3 squares (2 to 10 px
// either side). On rendered views this is as accurate as the detector's own
// CALIB_CB_ACCURACY in colour images, twice as accurate in ToF intensity images (0.07
// against 0.15 px RMS), and 4 times faster.
std::vector<cv::Point2f> board_corners(const cv::Mat& gray, cv::Size inner_corners,
                                       BoardSearch search) {
  std::vector<cv::Point2f> corners;
  const int flags = cv::CALIB_CB_NORMALIZE_IMAGE |
                    (search == BoardSearch::kThorough ? cv::CALIB_CB_EXHAUSTIVE : 0);
  if (!cv::findChessboardCornersSB(gray, inner_corners, corners, flags) ||
      !regular_grid(corners, inner_corners)) {
    return {};
  }
  const int half_window = std::clamp(
      static_cast<int>(std::lround(0.3 * corner_spacing(corners, inner_corners))), 2, 10);
  cv::cornerSubPix(gray, corners, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
  // The detector may start from either end of the board (a half turn leaves the grid of
  // corners in place), and not always from the same end in both cameras' images: start
  // from the end nearer the image's top left, the same end in two cameras that look the
  // same way.
  const cv::Point2f first_to_last = corners.back() - corners.front();
  if (first_to_last.x + first_to_last.y < 0.0f) std::reverse(corners.begin(), corners.end());
  return corners;
}

std::optional<PixelFormat> parse_color_mosaic(const std::string& text) {
  static const std::map<std::string, PixelFormat> kMosaics = {{"RG", PixelFormat::kBayerRggb8},
                                                              {"BG", PixelFormat::kBayerBggr8},
                                                              {"GR", PixelFormat::kBayerGrbg8},
                                                              {"GB", PixelFormat::kBayerGbrg8}};
  const auto found = kMosaics.find(text);
  if (found == kMosaics.end()) {
    throw Error(
        "--color-bayer: expected RG, BG, GR or GB (the first row's first two pixels), got '" +
        text + "'");
  }
  return found->second;
}

cv::Mat intensity_to_8bit(const cv::Mat& intensity) {
  cv::Mat values;
  intensity.reshape(1, 1).convertTo(values, CV_32F);
  std::vector<float> sorted(values.begin<float>(), values.end<float>());
  const auto at = [&sorted](double fraction) {
    auto nth = sorted.begin() + static_cast<std::ptrdiff_t>(fraction * (sorted.size() - 1));
    std::nth_element(sorted.begin(), nth, sorted.end());
    return static_cast<double>(*nth);
  };
  const double low = at(0.01);
  const double high = std::max(at(0.99), low + 1.0);
  cv::Mat scaled;
  intensity.convertTo(scaled, CV_8U, 255.0 / (high - low), -low * 255.0 / (high - low));
  return scaled;
}

BoardView find_board(const ViewFiles& files, cv::Size inner_corners,
                     std::optional<PixelFormat> mosaic) {
  const cv::Mat intensity = read_image(files.intensity);
  if (intensity.channels() != 1 || (intensity.depth() != CV_8U && intensity.depth() != CV_16U)) {
    throw Error(files.intensity.string() +
                ": expected a 1-channel 8- or 16-bit ToF intensity image, got " +
                std::to_string(intensity.channels()) + " channels");
  }
  const cv::Mat color = read_image(files.color);
  BoardView view;
  view.name = files.name;
  view.depth_size = intensity.size();
  view.color_size = color.size();
  view.depth_corners =
      board_corners(intensity_to_8bit(intensity), inner_corners, BoardSearch::kThorough);
  view.color_corners = board_corners(color_to_gray(color, mosaic, files.color), inner_corners,
                                     BoardSearch::kThorough);
  return view;
}

std::vector<BoardView> find_boards(const std::vector<ViewFiles>& views, cv::Size inner_corners,
                                   std::optional<PixelFormat> mosaic) {
  std::vector<BoardView> boards(views.size());
  std::vector<std::exception_ptr> errors(views.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      try {
        boards[i] = find_board(views[i], inner_corners, mosaic);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  });
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
  return boards;
}

}  // namespace tilth::calibrate
