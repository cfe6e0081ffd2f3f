// What every residue segmentation stage (segmentation.color_threshold and its variants)
// shares, so that a graph swaps them by type name: the ports, the input checks, the
// parameters of the last steps, and those steps from a raw residue decision to the
// outputs (speck removal, dilation, unknowns, soil depth) on bit masks.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "bit_mask.h"
#include "outside_fill.h"
#include "residue_kernels.h"
#include "roi/region_of_interest.h"
#include "tilth/frame.h"
#include "tilth/message_pool.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/param_spec.h"
#include "tilth/params.h"
#include "tilth/port_spec.h"

namespace tilth::segmentation {

enum ResidueInputPort { kColorInput = 0, kDepthInput = 1 };

std::vector<PortSpec> residue_inputs();   // color (RegisteredColor), depth (DepthImage)
std::vector<PortSpec> residue_outputs();  // mask (ResidueMask), soil_depth (DepthImage)

// Throws tilth::Error naming the input and what was expected: types, and colour registered
// onto the depth grid.
void check_residue_inputs(const RegisteredColor& color, const DepthImage& depth);

ParamSpec dilation_px_param();
ParamSpec speckle_px_param(std::int64_t default_px);
ParamSpec min_value_param();
ParamSpec smoothing_px_param();     // colours averaged over a (2r+1)^2 box first
ParamSpec segmented_roi_param();    // `roi`, null = the whole image
ParamSpec scored_every_px_param();  // the trees' grid (pixel_classifier, self_trained)

// 255 where the colour cannot be used: status not kValid, or every channel below min_value.
void mark_untrusted_color(const cv::Mat& bgr, const cv::Mat& status, int min_value,
                          cv::Mat& untrusted);

// 255 where the depth is NaN or not beyond the mounting surface (<= 0 mm), which no
// surface in front of the camera gives.
void mark_missing_depth(const cv::Mat& depth_mm, cv::Mat& missing);

// A residue segmentation's inputs, checked (check_residue_inputs), within the `area` it
// segments, and which of their pixels are unknown: `untrusted` colour
// (mark_untrusted_color), `missing` depth (mark_missing_depth), `unknown` either. The
// masks belong to the calling thread and hold until its next call.
struct ResidueInputs {
  cv::Rect area;     // of the depth grid
  cv::Mat bgr;       // the registered colour's, in `area`
  cv::Mat depth_mm;  // in `area`
  const cv::Mat& untrusted;
  const cv::Mat& missing;
  const cv::Mat& unknown;
};
ResidueInputs read_residue_inputs(const Frame& frame, int min_value, const cv::Rect& area);

class ResidueOutput {
 public:
  enum OutputPort { kMask = 0, kSoilDepth = 1 };

  // Reads dilation_px, speckle_px and roi.
  explicit ResidueOutput(const Params& params);

  // The part of a depth image of `size` to segment: the roi, and around it as far as the
  // outputs' last steps reach (smoothing, speckle, dilation), so that the roi's edge
  // pixels are segmented as they would be in a whole image. The outputs are unknown
  // outside it.
  cv::Rect area(cv::Size size) const;
  // The same for the frame's depth input.
  cv::Rect area(const Frame& frame) const;

  // `residue` (CV_8UC1, 255/0) is what the variant found in `area`, as the other images. Pixels
  // marked in `not_residue` (if not empty) are taken out of it first, so they cannot grow into
  // their neighbours; then as below. Nothing is allocated in the steady state.
  void emit(Frame& frame, const cv::Rect& area, const cv::Mat& residue, const cv::Mat& not_residue,
            const cv::Mat& unknown, const cv::Mat& depth_mm);

  // The same from bit masks (BitMask), `residue` consumed: specks narrower than
  // 2*speckle_px+1 go; the rest is dilated by dilation_px; pixels marked in `unknown`, and
  // those whose depth is NaN, become kUnknown; the depth of the remaining soil pixels is
  // the soil depth. Sets both outputs of `frame`, the size of its depth input.
  void emit(Frame& frame, const cv::Rect& area, BitMask& residue, const BitMask& unknown,
            const cv::Mat& depth_mm);

 private:
  const ResidueKernels& kernels_ = *available_residue_kernels().front();
  const int dilation_px_;
  const int speckle_px_;
  const RegionOfInterest roi_;
  MessagePool<ResidueMask> masks_;
  MessagePool<DepthImage> soil_depths_;
  OutsideFill outside_;
};

}  // namespace tilth::segmentation
