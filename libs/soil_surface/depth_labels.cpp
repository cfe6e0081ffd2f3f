// The surface is segmentation.depth_aided's with its defaults (a RANSAC plane through the
// farthest depths, or their envelope, then a Gaussian-weighted local surface of sigma 3 px
// over the pixels within 3 mm of it): the stage whose masks the simulator tests pin. Every
// pixel with depth may support it, as in depth_aided: the labels come before any colour
// model.
#include "depth_labels.h"

#include <cstdio>
#include <string>

#include <opencv2/imgproc.hpp>

#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::segmentation {
namespace {

constexpr double kSurfaceHeightMm = 3.0;
constexpr double kSurfaceSigmaPx = 3.0;

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

DepthLabelOptions checked(const DepthLabelOptions& options) {
  const std::string given = "soil within " + number(options.soil_within_mm) +
                            " mm, residue above " + number(options.residue_above_mm) +
                            " mm, edge " + std::to_string(options.edge_px) + " px, envelope " +
                            number(options.envelope_px) + " px";
  if (!(options.soil_within_mm > 0) || options.edge_px < 0 || !(options.envelope_px >= 0)) {
    throw Error("depth labels of " + given +
                " (expected a soil band above 0 mm, an edge and an envelope of 0 px or more)");
  }
  if (!(options.residue_above_mm > options.soil_within_mm)) {
    throw Error("depth labels of " + given +
                " (expected residue above the soil band: residue above > soil within)");
  }
  return options;
}

}  // namespace

DepthLabels::DepthLabels(const DepthLabelOptions& options)
    : options_(checked(options)),
      surface_(kSurfaceHeightMm, kSurfaceHeightMm, kSurfaceSigmaPx, options.envelope_px),
      edge_(cv::getStructuringElement(cv::MORPH_RECT,
                                      {2 * options.edge_px + 1, 2 * options.edge_px + 1})) {}

void DepthLabels::label(const cv::Mat& depth_mm, cv::Mat& labels) const {
  thread_local cv::Mat has_depth, missing, height, residue, soil, band, near_other;
  cv::compare(depth_mm, 0.0, has_depth, cv::CMP_GT);  // NaN: no
  cv::bitwise_not(has_depth, missing);
  surface_.heights(depth_mm, missing, has_depth, height);

  // NaN heights (no depth, no surface) compare false: in no class and not the band.
  cv::compare(height, options_.residue_above_mm, residue, cv::CMP_GT);
  cv::inRange(height, -options_.soil_within_mm, options_.soil_within_mm, soil);
  cv::compare(height, height, band, cv::CMP_EQ);  // has a height
  cv::bitwise_and(band, ~(residue | soil), band);

  labels.create(depth_mm.size(), CV_8UC1);
  labels.setTo(ResidueMask::kUnknown);
  cv::dilate(soil | band, near_other, edge_);
  labels.setTo(ResidueMask::kResidue, residue & ~near_other);
  cv::dilate(residue | band, near_other, edge_);
  labels.setTo(ResidueMask::kSoil, soil & ~near_other);
}

}  // namespace tilth::segmentation
