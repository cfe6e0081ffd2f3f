#include "view_mosaic.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "color/color_conversion.h"

namespace tilth::view {
namespace {

const cv::Scalar kResidueColor(40, 40, 255);
const cv::Scalar kRoiColor(0, 230, 255);
const cv::Scalar kEdgeColor(255, 0, 255);
const cv::Scalar kValidColor(80, 230, 80);
const cv::Scalar kInvalidColor(60, 60, 255);
// A depth step of more than this between neighbouring pixels is drawn as an edge: straw
// lying on soil stands 3-10 mm above it, and ToF noise at 0.5 m is about 1 mm.
constexpr double kEdgeStepMm = 6.0;

void caption(cv::Mat& panel, const std::string& text, int line, const cv::Scalar& color) {
  const double scale = panel.cols >= 480 ? 0.6 : 0.45;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  const cv::Point origin(6, 6 + (line + 1) * (size.height + baseline + 4));
  cv::rectangle(panel, origin + cv::Point(-3, baseline + 2),
                origin + cv::Point(size.width + 3, -size.height - 3), cv::Scalar::all(0),
                cv::FILLED);
  cv::putText(panel, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, color, 1, cv::LINE_AA);
}

cv::Mat empty_panel(cv::Size panel, const std::string& title) {
  cv::Mat image(panel, CV_8UC3, cv::Scalar::all(40));
  caption(image, title + ": not connected", 0, cv::Scalar::all(200));
  return image;
}

cv::Mat shrink(const cv::Mat& image, cv::Size panel, int interpolation) {
  cv::Mat out;
  cv::resize(image, out, panel, 0, 0, interpolation);
  return out;
}

// The registered colour at panel size, or grey where there is none.
cv::Mat registered_base(const FrameMessages& frame, cv::Size panel) {
  if (frame.registered == nullptr) return cv::Mat(panel, CV_8UC3, cv::Scalar::all(60));
  return shrink(frame.registered->bgr, panel, cv::INTER_LINEAR);
}

cv::Size depth_grid(const FrameMessages& frame) {
  if (frame.registered != nullptr) return frame.registered->bgr.size();
  if (frame.mask != nullptr) return frame.mask->values.size();
  if (frame.depth != nullptr) return frame.depth->mm.size();
  return {};
}

// The colour camera's image fitted inside the panel, its aspect ratio kept.
cv::Mat color_panel(const FrameMessages& frame, cv::Size panel) {
  if (frame.color == nullptr) return empty_panel(panel, "colour camera");
  cv::Mat bgr;
  color::to_bgr(frame.color->pixels, frame.color->format, bgr);
  const double scale = std::min(static_cast<double>(panel.width) / bgr.cols,
                                static_cast<double>(panel.height) / bgr.rows);
  const cv::Size fitted(std::max(1, cvRound(bgr.cols * scale)),
                        std::max(1, cvRound(bgr.rows * scale)));
  cv::Mat image(panel, CV_8UC3, cv::Scalar::all(0));
  cv::resize(bgr,
             image(cv::Rect((panel.width - fitted.width) / 2, (panel.height - fitted.height) / 2,
                            fitted.width, fitted.height)),
             fitted, 0, 0, cv::INTER_LINEAR);
  caption(image,
          "colour camera " + std::to_string(frame.color->pixels.cols) + "x" +
              std::to_string(frame.color->pixels.rows),
          0, cv::Scalar::all(255));
  return image;
}

std::string distance_text(const GroundDistance& distance) {
  char text[96];
  if (distance.valid) {
    std::snprintf(text, sizeof text, "%.1f mm%s  soil %.0f %%", distance.distance_mm,
                  distance.held ? " (held)" : "", 100.0 * distance.soil_fraction);
  } else {
    std::snprintf(text, sizeof text, "invalid: %s  soil %.0f %%",
                  std::string(to_string(distance.cause)).c_str(), 100.0 * distance.soil_fraction);
  }
  return text;
}

cv::Mat mask_panel(const FrameMessages& frame, cv::Size panel, std::optional<cv::Rect> roi) {
  cv::Mat image = registered_base(frame, panel);
  if (frame.mask != nullptr) {
    const cv::Mat mask = shrink(frame.mask->values, panel, cv::INTER_NEAREST);
    cv::Mat tinted;
    cv::addWeighted(image, 0.45, cv::Mat(panel, CV_8UC3, kResidueColor), 0.55, 0.0, tinted);
    tinted.copyTo(image, mask == ResidueMask::kResidue);
    cv::Mat dimmed = image * 0.5;
    dimmed.copyTo(image, mask == ResidueMask::kUnknown);
  }
  const cv::Size grid = depth_grid(frame);
  if (roi && !grid.empty()) {
    const double sx = static_cast<double>(panel.width) / grid.width;
    const double sy = static_cast<double>(panel.height) / grid.height;
    cv::rectangle(image,
                  cv::Rect(cvRound(roi->x * sx), cvRound(roi->y * sy), cvRound(roi->width * sx),
                           cvRound(roi->height * sy)),
                  kRoiColor, 2);
  }
  caption(image,
          frame.mask != nullptr ? "residue (red), region (yellow)" : "residue: not connected", 0,
          cv::Scalar::all(255));
  if (frame.distance != nullptr) {
    caption(image, distance_text(*frame.distance), 1,
            frame.distance->valid ? kValidColor : kInvalidColor);
  }
  return image;
}

cv::Mat depth_panel(const FrameMessages& frame, cv::Size panel) {
  if (frame.depth == nullptr) return empty_panel(panel, "depth");
  const cv::Mat depth = shrink(frame.depth->mm, panel, cv::INTER_NEAREST);
  const cv::Mat measured = depth == depth;  // NaN compares unequal
  double lo = 0.0;
  double hi = 0.0;
  cv::minMaxLoc(depth, &lo, &hi, nullptr, nullptr, measured);
  if (hi <= lo) hi = lo + 1.0;
  cv::Mat scaled;
  depth.convertTo(scaled, CV_8U, 255.0 / (hi - lo), -lo * 255.0 / (hi - lo));
  cv::Mat image;
  cv::applyColorMap(scaled, image, cv::COLORMAP_TURBO);
  image.setTo(cv::Scalar::all(0), ~measured);
  char text[64];
  std::snprintf(text, sizeof text, "depth %.0f (blue) - %.0f mm (red)", lo, hi);
  caption(image, text, 0, cv::Scalar::all(255));
  return image;
}

cv::Mat edges_panel(const FrameMessages& frame, cv::Size panel) {
  cv::Mat gray;
  cv::cvtColor(registered_base(frame, panel), gray, cv::COLOR_BGR2GRAY);
  cv::Mat image;
  cv::cvtColor(gray, image, cv::COLOR_GRAY2BGR);
  if (frame.depth != nullptr) {
    // A one-pixel line where the depth steps to the next pixel right or down (NaN, no
    // depth, makes no step).
    const cv::Mat depth = shrink(frame.depth->mm, panel, cv::INTER_NEAREST);
    const int cols = depth.cols;
    const int rows = depth.rows;
    cv::Mat edges = cv::Mat::zeros(depth.size(), CV_8UC1);
    cv::Mat step = cv::abs(depth.colRange(1, cols) - depth.colRange(0, cols - 1)) > kEdgeStepMm;
    cv::Mat right = edges.colRange(1, cols);
    right |= step;
    step = cv::abs(depth.rowRange(1, rows) - depth.rowRange(0, rows - 1)) > kEdgeStepMm;
    cv::Mat down = edges.rowRange(1, rows);
    down |= step;
    image.setTo(kEdgeColor, edges);
  }
  caption(image, "registration: depth edges (magenta) on colour", 0, cv::Scalar::all(255));
  return image;
}

}  // namespace

cv::Mat render_mosaic(const FrameMessages& frame, cv::Size panel, std::optional<cv::Rect> roi) {
  cv::Mat top;
  cv::Mat bottom;
  cv::hconcat(color_panel(frame, panel), mask_panel(frame, panel, roi), top);
  cv::hconcat(depth_panel(frame, panel), edges_panel(frame, panel), bottom);
  cv::Mat mosaic;
  cv::vconcat(top, bottom, mosaic);
  return mosaic;
}

std::vector<unsigned char> encode_jpeg(const cv::Mat& image, int quality) {
  std::vector<unsigned char> bytes;
  cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return bytes;
}

}  // namespace tilth::view
