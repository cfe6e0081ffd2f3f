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

// Each draw_* fills `panel`, a view into the mosaic, in place, from the frame's images
// resized to the panel once.
struct PanelImages {
  cv::Mat registered;  // BGR, grey where there is none
  cv::Mat depth;       // mm, NaN where none; empty without depth
};

void draw_empty(cv::Mat panel, const std::string& title) {
  panel.setTo(cv::Scalar::all(40));
  caption(panel, title + ": not connected", 0, cv::Scalar::all(200));
}

cv::Mat shrink(const cv::Mat& image, cv::Size panel, int interpolation) {
  cv::Mat out;
  cv::resize(image, out, panel, 0, 0, interpolation);
  return out;
}

PanelImages panel_images(const FrameMessages& frame, cv::Size panel) {
  PanelImages images;
  if (frame.registered == nullptr) {
    images.registered = cv::Mat(panel, CV_8UC3, cv::Scalar::all(60));
  } else {
    images.registered = shrink(frame.registered->bgr, panel, cv::INTER_LINEAR);
  }
  if (frame.depth != nullptr) images.depth = shrink(frame.depth->mm, panel, cv::INTER_NEAREST);
  return images;
}

cv::Size depth_grid(const FrameMessages& frame) {
  if (frame.registered != nullptr) return frame.registered->bgr.size();
  if (frame.mask != nullptr) return frame.mask->values.size();
  if (frame.depth != nullptr) return frame.depth->mm.size();
  return {};
}

// The colour camera's image fitted inside the panel, its aspect ratio kept.
void draw_color(const FrameMessages& frame, cv::Mat panel) {
  if (frame.color == nullptr) return draw_empty(panel, "colour camera");
  cv::Mat bgr;
  color::to_bgr(frame.color->pixels, frame.color->format, bgr);
  const double scale = std::min(static_cast<double>(panel.cols) / bgr.cols,
                                static_cast<double>(panel.rows) / bgr.rows);
  const cv::Size fitted(std::max(1, cvRound(bgr.cols * scale)),
                        std::max(1, cvRound(bgr.rows * scale)));
  panel.setTo(cv::Scalar::all(0));
  cv::Mat inside = panel(cv::Rect((panel.cols - fitted.width) / 2, (panel.rows - fitted.height) / 2,
                                  fitted.width, fitted.height));
  cv::resize(bgr, inside, fitted, 0, 0, cv::INTER_LINEAR);
  caption(panel,
          "colour camera " + std::to_string(frame.color->pixels.cols) + "x" +
              std::to_string(frame.color->pixels.rows),
          0, cv::Scalar::all(255));
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

void draw_mask(const FrameMessages& frame, const PanelImages& images, std::optional<cv::Rect> roi,
               cv::Mat panel) {
  images.registered.copyTo(panel);
  if (frame.mask != nullptr) {
    const cv::Mat mask = shrink(frame.mask->values, panel.size(), cv::INTER_NEAREST);
    cv::Mat tinted;
    cv::addWeighted(panel, 0.45, cv::Mat(panel.size(), CV_8UC3, kResidueColor), 0.55, 0.0, tinted);
    tinted.copyTo(panel, mask == ResidueMask::kResidue);
    cv::Mat dimmed = panel * 0.5;
    dimmed.copyTo(panel, mask == ResidueMask::kUnknown);
  }
  const cv::Size grid = depth_grid(frame);
  if (roi && !grid.empty()) {
    const double sx = static_cast<double>(panel.cols) / grid.width;
    const double sy = static_cast<double>(panel.rows) / grid.height;
    cv::rectangle(panel,
                  cv::Rect(cvRound(roi->x * sx), cvRound(roi->y * sy), cvRound(roi->width * sx),
                           cvRound(roi->height * sy)),
                  kRoiColor, 2);
  }
  caption(panel,
          frame.mask != nullptr ? "residue (red), region (yellow)" : "residue: not connected", 0,
          cv::Scalar::all(255));
  if (frame.distance != nullptr) {
    caption(panel, distance_text(*frame.distance), 1,
            frame.distance->valid ? kValidColor : kInvalidColor);
  }
}

void draw_depth(const PanelImages& images, cv::Mat panel) {
  if (images.depth.empty()) return draw_empty(panel, "depth");
  const cv::Mat& depth = images.depth;
  const cv::Mat measured = depth == depth;  // NaN compares unequal
  double lo = 0.0;
  double hi = 0.0;
  cv::minMaxLoc(depth, &lo, &hi, nullptr, nullptr, measured);
  if (hi <= lo) hi = lo + 1.0;
  cv::Mat scaled;
  depth.convertTo(scaled, CV_8U, 255.0 / (hi - lo), -lo * 255.0 / (hi - lo));
  cv::applyColorMap(scaled, panel, cv::COLORMAP_TURBO);
  panel.setTo(cv::Scalar::all(0), ~measured);
  char text[64];
  std::snprintf(text, sizeof text, "depth %.0f (blue) - %.0f mm (red)", lo, hi);
  caption(panel, text, 0, cv::Scalar::all(255));
}

void draw_edges(const PanelImages& images, cv::Mat panel) {
  cv::Mat gray;
  cv::cvtColor(images.registered, gray, cv::COLOR_BGR2GRAY);
  cv::cvtColor(gray, panel, cv::COLOR_GRAY2BGR);
  if (!images.depth.empty()) {
    // A one-pixel line where the depth steps to the next pixel right or down (NaN, no
    // depth, makes no step).
    const cv::Mat& depth = images.depth;
    const int cols = depth.cols;
    const int rows = depth.rows;
    cv::Mat edges = cv::Mat::zeros(depth.size(), CV_8UC1);
    cv::Mat step = cv::abs(depth.colRange(1, cols) - depth.colRange(0, cols - 1)) > kEdgeStepMm;
    cv::Mat right = edges.colRange(1, cols);
    right |= step;
    step = cv::abs(depth.rowRange(1, rows) - depth.rowRange(0, rows - 1)) > kEdgeStepMm;
    cv::Mat down = edges.rowRange(1, rows);
    down |= step;
    panel.setTo(kEdgeColor, edges);
  }
  caption(panel, "registration: depth edges (magenta) on colour", 0, cv::Scalar::all(255));
}

}  // namespace

void render_mosaic(const FrameMessages& frame, cv::Size panel, std::optional<cv::Rect> roi,
                   cv::Mat& mosaic) {
  mosaic.create(panel.height * 2, panel.width * 2, CV_8UC3);
  const auto at = [&](int column, int row) {
    return mosaic(cv::Rect(column * panel.width, row * panel.height, panel.width, panel.height));
  };
  const PanelImages images = panel_images(frame, panel);
  draw_color(frame, at(0, 0));
  draw_mask(frame, images, roi, at(1, 0));
  draw_depth(images, at(0, 1));
  draw_edges(images, at(1, 1));
}

std::vector<unsigned char> encode_jpeg(const cv::Mat& image, int quality) {
  std::vector<unsigned char> bytes;
  cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return bytes;
}

}  // namespace tilth::view
