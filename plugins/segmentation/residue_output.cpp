#include "residue_output.h"

#include <algorithm>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pixel_classifier/residue_classifier.h"
#include "residue_rows.h"
#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

std::string size_text(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

}  // namespace

std::vector<PortSpec> residue_inputs() {
  return {
      PortSpec::of<RegisteredColor>("color", "colour on the depth grid, with per-pixel status"),
      PortSpec::of<DepthImage>("depth", "depth in mm, NaN where none"),
  };
}

std::vector<PortSpec> residue_outputs() {
  return {
      PortSpec::of<ResidueMask>("mask", "255 residue (dilated), 0 soil, 128 unknown"),
      PortSpec::of<DepthImage>("soil_depth", "depth where the mask says soil, NaN elsewhere"),
  };
}

void check_residue_inputs(const RegisteredColor& color, const DepthImage& depth) {
  if (depth.mm.type() != CV_32FC1) {
    throw Error("input 'depth': expected a CV_32FC1 image in mm, got type " +
                std::to_string(depth.mm.type()));
  }
  if (color.bgr.type() != CV_8UC3 || color.status.type() != CV_8UC1) {
    throw Error("input 'color': expected bgr CV_8UC3 and status CV_8UC1, got types " +
                std::to_string(color.bgr.type()) + " and " + std::to_string(color.status.type()));
  }
  if (color.bgr.size() != depth.mm.size() || color.status.size() != depth.mm.size()) {
    throw Error("input 'color': bgr " + size_text(color.bgr) + " and status " +
                size_text(color.status) + " do not match the " + size_text(depth.mm) +
                " depth image (expected colour registered onto the depth grid)");
  }
}

ParamSpec dilation_px_param() {
  return ParamSpec::integer("dilation_px", 2)
      .range(0, 32)
      .in_unit("px")
      .describe("pixels within this distance of residue are residue too; 0 = no dilation");
}

ParamSpec scored_every_px_param() {
  return ParamSpec::integer("scored_every_px", kScoredEveryPx)
      .range(1, kMaxScoredEveryPx)
      .in_unit("px")
      .describe(
          "the trees score every n-th pixel of every n-th row, and the pixels "
          "between them where those disagree; 1 = every pixel");
}

ParamSpec speckle_px_param(std::int64_t default_px) {
  return ParamSpec::integer("speckle_px", default_px)
      .range(0, 8)
      .in_unit("px")
      .describe(
          "residue narrower than 2*speckle_px+1 px is dropped before dilation "
          "(noise, demosaicing specks); 0 = keep all");
}

ParamSpec smoothing_px_param() {
  return ParamSpec::integer("smoothing_px", 1)
      .range(0, 3)
      .in_unit("px")
      .describe("colours are averaged over a (2r+1)^2 box first; 0 = each pixel's own");
}

ParamSpec segmented_roi_param() { return roi_param(RegionOfInterest::Whole::kImage); }

ParamSpec min_value_param() {
  return ParamSpec::integer("min_value", 0)
      .range(0, 255)
      .describe("pixels whose brightest channel is below this are unknown (deep shadow)");
}

void mark_untrusted_color(const cv::Mat& bgr, const cv::Mat& status, int min_value,
                          cv::Mat& untrusted) {
  cv::compare(status, RegisteredColor::kValid, untrusted, cv::CMP_NE);
  if (min_value == 0) return;
  thread_local cv::Mat dark;
  cv::inRange(bgr, cv::Scalar::all(0), cv::Scalar::all(min_value - 1), dark);
  cv::bitwise_or(untrusted, dark, untrusted);
}

void mark_missing_depth(const cv::Mat& depth_mm, cv::Mat& missing) {
  // Also true for NaN, which compares false with everything.
  cv::compare(depth_mm, 0.0, missing, cv::CMP_GT);
  cv::bitwise_not(missing, missing);
}

ResidueInputs read_residue_inputs(const Frame& frame, int min_value, const cv::Rect& area) {
  const auto& color = frame.input<RegisteredColor>(kColorInput);
  const auto& depth = frame.input<DepthImage>(kDepthInput);
  check_residue_inputs(color, depth);
  const cv::Mat bgr = color.bgr(area);
  const cv::Mat depth_mm = depth.mm(area);
  thread_local cv::Mat untrusted, missing, unknown;
  mark_untrusted_color(bgr, color.status(area), min_value, untrusted);
  mark_missing_depth(depth_mm, missing);
  cv::bitwise_or(untrusted, missing, unknown);
  return {area, bgr, depth_mm, untrusted, missing, unknown};
}

ResidueOutput::ResidueOutput(const Params& params)
    : dilation_px_(static_cast<int>(params.integer("dilation_px"))),
      speckle_px_(static_cast<int>(params.integer("speckle_px"))),
      roi_(params.json("roi"), RegionOfInterest::Whole::kImage) {}

cv::Rect ResidueOutput::area(cv::Size size) const {
  return roi_.around(size, RegionOfInterest::kMarginPx);
}

cv::Rect ResidueOutput::area(const Frame& frame) const {
  return area(frame.input<DepthImage>(kDepthInput).mm.size());
}

void ResidueOutput::emit(Frame& frame, const cv::Rect& area, const cv::Mat& residue,
                         const cv::Mat& not_residue, const cv::Mat& unknown,
                         const cv::Mat& depth_mm) {
  const int rows = depth_mm.rows;
  const int cols = depth_mm.cols;
  thread_local BitMask residue_bits, unknown_bits;
  residue_bits.resize(rows, cols);
  unknown_bits.resize(rows, cols);
  for (int y = 0; y < rows; ++y) {
    std::uint64_t* residue_row = residue_bits.row(y);
    std::uint64_t* unknown_row = unknown_bits.row(y);
    for (int x = 0, word = 0; x < cols; x += 64, ++word) {
      const int count = std::min(64, cols - x);
      std::uint64_t bits = marked_bits(residue.ptr<std::uint8_t>(y) + x, count);
      if (!not_residue.empty()) bits &= ~marked_bits(not_residue.ptr<std::uint8_t>(y) + x, count);
      residue_row[word] = bits;
      unknown_row[word] = marked_bits(unknown.ptr<std::uint8_t>(y) + x, count);
    }
  }
  emit(frame, area, residue_bits, unknown_bits, depth_mm);
}

void ResidueOutput::emit(Frame& frame, const cv::Rect& area, BitMask& residue,
                         const BitMask& unknown, const cv::Mat& depth_mm) {
  const DepthImage& depth = frame.input<DepthImage>(kDepthInput);
  auto mask = masks_.acquire();
  auto soil = soil_depths_.acquire();
  soil->rig = depth.rig;  // the soil's depth is the depth's
  const std::uint8_t* const mask_before = mask->values.data;
  const std::uint8_t* const soil_before = soil->mm.data;
  reuse_or_create(mask->values, depth.mm.rows, depth.mm.cols, CV_8UC1);
  mask->segmented = area;
  reuse_or_create(soil->mm, depth.mm.rows, depth.mm.cols, CV_32FC1);
  outside_.fill(mask->values, mask_before, area, ResidueMask::kUnknown);
  outside_.fill(soil->mm, soil_before, area, std::numeric_limits<float>::quiet_NaN());
  cv::Mat mask_area = mask->values(area);
  cv::Mat soil_area = soil->mm(area);

  // An opening (erosion, then dilation by the same square) drops the specks; its
  // dilation and the edge dilation that follows add up to one square.
  thread_local BitMask morphology;
  residue.erode(speckle_px_, morphology);
  residue.dilate(speckle_px_ + dilation_px_, morphology);
  for (int y = 0; y < depth_mm.rows; ++y) {
    kernels_.write_residue_row(unknown.row(y), residue.row(y), depth_mm.ptr<float>(y),
                               depth_mm.cols, mask_area.ptr<std::uint8_t>(y),
                               soil_area.ptr<float>(y));
  }

  frame.set_output(kMask, mask);
  frame.set_output(kSoilDepth, soil);
}

}  // namespace tilth::segmentation
