// segmentation.color_threshold: the paper's residue segmentation (section 2.4) --
// colour conversion, in-range test, binary residue mask, dilation, then the depth with the
// residue taken out.
//
//   color ──► convert (hsv|lab|bgr) ──► in residue range? ──► despeckle ──► dilate ──┐
//     │                                                                ├──► mask
//     └──► trusted colour? (status kValid, not darker than min_value) ──┤
//   depth ──► has depth? ───────────────────────────────────────────────┴──► soil_depth
//
// Invariant: a pixel is soil only when its colour is trusted, it has depth, and no pixel
// within dilation_px of it (chessboard distance, so a square kernel) has a residue colour.
// The dilation is what keeps straw edges, and the ToF pixels that mix straw and soil
// depth along them, out of the soil depth.
//
//   "segment": {"type": "segmentation.color_threshold",
//               "params": {"color_space": "hsv", "residue_lower": [18, 40, 50],
//                          "residue_upper": [40, 255, 255], "dilation_px": 2}}
#include "color_threshold.h"

#include <algorithm>
#include <array>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "tilth/error.h"
#include "tilth/message_pool.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/plugin.h"

namespace tilth::segmentation {
namespace {

enum class ColorSpace { kHsv, kLab, kBgr };

// The defaults are boxes around reference colours of dry wheat straw and of soils, lit
// and in shadow (docs/segmentation.md has the table): straw is yellow (OpenCV hue 20-23),
// soils are redder (hue 9-15). Below V 50 one grey level moves the hue by more than an
// OpenCV unit, so darker pixels are left to the soil side.
struct ColorSpaceInfo {
  const char* name;
  std::array<const char*, 3> channels;
  std::array<int, 3> residue_lower;
  std::array<int, 3> residue_upper;
};

constexpr std::array<ColorSpaceInfo, 3> kColorSpaces{{
    {"hsv", {"H", "S", "V"}, {18, 40, 50}, {40, 255, 255}},
    {"lab", {"L", "a", "b"}, {50, 110, 140}, {255, 132, 255}},
    {"bgr", {"B", "G", "R"}, {0, 140, 160}, {255, 255, 255}},
}};

const ColorSpaceInfo& info(ColorSpace space) { return kColorSpaces[static_cast<int>(space)]; }

ColorSpace parse_color_space(const std::string& name) {
  for (std::size_t i = 0; i < kColorSpaces.size(); ++i) {
    if (name == kColorSpaces[i].name) return static_cast<ColorSpace>(i);
  }
  throw Error("parameter 'color_space': expected one of 'hsv', 'lab', 'bgr', got '" + name + "'");
}

cv::Scalar residue_bound(const Params& params, const std::string& name,
                         const std::array<int, 3>& fallback) {
  const nlohmann::json& value = params.json(name);
  if (value.is_null()) return {double(fallback[0]), double(fallback[1]), double(fallback[2])};
  const bool shaped =
      value.is_array() && value.size() == 3 &&
      std::all_of(value.begin(), value.end(), [](const nlohmann::json& channel) {
        return channel.is_number_integer() && channel.get<int>() >= 0 && channel.get<int>() <= 255;
      });
  if (!shaped) {
    throw Error("parameter '" + name +
                "': expected null or an array of 3 integers in [0, 255] (the colour space's "
                "8-bit channels), got " +
                value.dump());
  }
  return {value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
}

void check_bounds_ordered(const cv::Scalar& lower, const cv::Scalar& upper, ColorSpace space) {
  for (int channel = 0; channel < 3; ++channel) {
    if (lower[channel] > upper[channel]) {
      throw Error("parameters 'residue_lower' and 'residue_upper': channel " +
                  std::string(info(space).channels[channel]) + " lower bound " +
                  std::to_string(int(lower[channel])) + " > upper bound " +
                  std::to_string(int(upper[channel])) + " (expected lower <= upper)");
    }
  }
}

std::string size_text(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

void check_inputs(const RegisteredColor& color, const DepthImage& depth) {
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

// Per-thread working images: the stage runs frames concurrently, and these keep their
// buffers from one frame to the next on the same thread.
struct Scratch {
  cv::Mat converted;
  cv::Mat residue;
  cv::Mat untrusted;  // 255 where the colour cannot be used
  cv::Mat dark;       // 255 where every channel is below min_value
  cv::Mat unknown;    // 255 where the colour cannot be used or there is no depth
  cv::Mat soil;       // 255 where the mask says soil
};

class ColorThreshold final : public Transform {
 public:
  enum InputPort { kColor = 0, kDepth = 1 };
  enum OutputPort { kMask = 0, kSoilDepth = 1 };

  explicit ColorThreshold(const StageContext& context)
      : space_(parse_color_space(context.params.string("color_space"))),
        lower_(residue_bound(context.params, "residue_lower", info(space_).residue_lower)),
        upper_(residue_bound(context.params, "residue_upper", info(space_).residue_upper)),
        dilation_px_(static_cast<int>(context.params.integer("dilation_px"))),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        kernel_(cv::getStructuringElement(cv::MORPH_RECT,
                                          {2 * dilation_px_ + 1, 2 * dilation_px_ + 1})),
        speckle_kernel_(cv::getStructuringElement(
            cv::MORPH_RECT, {2 * static_cast<int>(context.params.integer("speckle_px")) + 1,
                             2 * static_cast<int>(context.params.integer("speckle_px")) + 1})),
        despeckle_(context.params.integer("speckle_px") > 0) {
    check_bounds_ordered(lower_, upper_, space_);
  }

  void process(Frame& frame) override {
    const auto& color = frame.input<RegisteredColor>(kColor);
    const auto& depth = frame.input<DepthImage>(kDepth);
    check_inputs(color, depth);

    auto mask = masks_.acquire();
    auto soil = soil_depths_.acquire();
    reuse_or_create(mask->values, depth.mm.rows, depth.mm.cols, CV_8UC1);
    reuse_or_create(soil->mm, depth.mm.rows, depth.mm.cols, CV_32FC1);

    thread_local Scratch scratch;
    mark_untrusted(color, scratch);
    const cv::Mat& converted = convert(color.bgr, scratch.converted);
    // Without dilation the in-range result is the mask itself, before unknowns are marked.
    cv::Mat& residue = dilation_px_ > 0 ? scratch.residue : mask->values;
    cv::inRange(converted, lower_, upper_, residue);
    // An untrusted colour may fall in the range by chance (an occluded pixel carries the
    // colour of what hides it); it must not grow into its neighbours.
    cv::subtract(residue, scratch.untrusted, residue);  // saturates: 255 - 255 = 0
    // Isolated specks (sensor noise, demosaicing artefacts on soil texture) would
    // otherwise each be dilated into a square of lost soil.
    if (despeckle_) cv::morphologyEx(residue, residue, cv::MORPH_OPEN, speckle_kernel_);
    if (dilation_px_ > 0) cv::dilate(residue, mask->values, kernel_);
    label_and_subtract(depth.mm, scratch, mask->values, soil->mm);

    frame.set_output(kMask, mask);
    frame.set_output(kSoilDepth, soil);
  }

 private:
  const cv::Mat& convert(const cv::Mat& bgr, cv::Mat& converted) const {
    switch (space_) {
      case ColorSpace::kHsv:
        cv::cvtColor(bgr, converted, cv::COLOR_BGR2HSV);
        return converted;
      case ColorSpace::kLab:
        cv::cvtColor(bgr, converted, cv::COLOR_BGR2Lab);
        return converted;
      case ColorSpace::kBgr:
        break;
    }
    return bgr;
  }

  void mark_untrusted(const RegisteredColor& color, Scratch& scratch) const {
    cv::compare(color.status, RegisteredColor::kValid, scratch.untrusted, cv::CMP_NE);
    if (min_value_ == 0) return;
    cv::inRange(color.bgr, cv::Scalar::all(0), cv::Scalar::all(min_value_ - 1), scratch.dark);
    cv::bitwise_or(scratch.untrusted, scratch.dark, scratch.untrusted);
  }

  // Marks the unknowns in the dilated residue mask (255/0) and writes the soil pixels' depth.
  static void label_and_subtract(const cv::Mat& depth_mm, Scratch& scratch, cv::Mat& mask,
                                 cv::Mat& soil_mm) {
    // NaN is the one value unequal to itself (OpenCV's CMP_NE does not say so for NaN).
    cv::compare(depth_mm, depth_mm, scratch.unknown, cv::CMP_EQ);
    cv::bitwise_not(scratch.unknown, scratch.unknown);
    cv::bitwise_or(scratch.unknown, scratch.untrusted, scratch.unknown);
    mask.setTo(ResidueMask::kUnknown, scratch.unknown);
    cv::compare(mask, ResidueMask::kSoil, scratch.soil, cv::CMP_EQ);
    soil_mm.setTo(std::numeric_limits<float>::quiet_NaN());
    depth_mm.copyTo(soil_mm, scratch.soil);
  }

  const ColorSpace space_;
  const cv::Scalar lower_;
  const cv::Scalar upper_;
  const int dilation_px_;
  const int min_value_;
  const cv::Mat kernel_;
  const cv::Mat speckle_kernel_;
  const bool despeckle_;
  MessagePool<ResidueMask> masks_;
  MessagePool<DepthImage> soil_depths_;
};

}  // namespace

StageDescriptor describe_color_threshold() {
  StageDescriptor d;
  d.type = "segmentation.color_threshold";
  d.summary = "residue mask from a colour range, dilated; soil depth = depth outside it";
  d.inputs = {
      PortSpec::of<RegisteredColor>("color", "colour on the depth grid, with per-pixel status"),
      PortSpec::of<DepthImage>("depth", "depth in mm, NaN where none"),
  };
  d.outputs = {
      PortSpec::of<ResidueMask>("mask", "255 residue (dilated), 0 soil, 128 unknown"),
      PortSpec::of<DepthImage>("soil_depth", "depth where the mask says soil, NaN elsewhere"),
  };
  d.params = {
      ParamSpec::choice("color_space", {"hsv", "lab", "bgr"}, "hsv")
          .describe("colour space of the residue range (OpenCV 8-bit: H 0-180, Lab 0-255)"),
      ParamSpec::json("residue_lower", nullptr)
          .describe("lowest residue colour [c0, c1, c2], inclusive; null = hsv [18, 40, 50], "
                    "lab [50, 110, 140], bgr [0, 140, 160]"),
      ParamSpec::json("residue_upper", nullptr)
          .describe("highest residue colour [c0, c1, c2], inclusive; null = hsv [40, 255, 255], "
                    "lab [255, 132, 255], bgr [255, 255, 255]"),
      ParamSpec::integer("dilation_px", 2)
          .range(0, 32)
          .in_unit("px")
          .describe("pixels within this distance of residue are residue too; 0 = no dilation"),
      ParamSpec::integer("speckle_px", 0)
          .range(0, 8)
          .in_unit("px")
          .describe("residue narrower than 2*speckle_px+1 px is dropped before dilation "
                    "(noise, demosaicing specks); 0 = keep all"),
      ParamSpec::integer("min_value", 0)
          .range(0, 255)
          .describe("pixels whose brightest channel is below this are unknown (deep shadow)"),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<ColorThreshold>();
  return d;
}

TILTH_STAGE(describe_color_threshold());

}  // namespace tilth::segmentation
