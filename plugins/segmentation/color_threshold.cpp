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
// Per frame the conversion and in-range test are one lookup per pixel in a table of every
// BGR colour (ColorRangeTable, made when the stage starts with OpenCV's own cvtColor and
// inRange, so the mask is theirs exactly; looked up with the widest vectors the CPU has),
// and the masks are bits, 64 pixels to a word (BitMask), for the morphology.
//
//   "segment": {"type": "segmentation.color_threshold",
//               "params": {"color_space": "hsv", "residue_lower": [18, 40, 50],
//                          "residue_upper": [40, 255, 255], "dilation_px": 2}}
#include "color_threshold.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "bit_mask.h"
#include "color_range_table.h"
#include "residue_kernels.h"
#include "residue_output.h"
#include "residue_rows.h"
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

std::array<int, 3> residue_bound(const Params& params, const std::string& name,
                                 const std::array<int, 3>& fallback) {
  const nlohmann::json& value = params.json(name);
  if (value.is_null()) return fallback;
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
  return {value[0].get<int>(), value[1].get<int>(), value[2].get<int>()};
}

void check_bounds_ordered(const std::array<int, 3>& lower, const std::array<int, 3>& upper,
                          ColorSpace space) {
  for (int channel = 0; channel < 3; ++channel) {
    if (lower[channel] > upper[channel]) {
      throw Error("parameters 'residue_lower' and 'residue_upper': channel " +
                  std::string(info(space).channels[channel]) + " lower bound " +
                  std::to_string(lower[channel]) + " > upper bound " +
                  std::to_string(upper[channel]) + " (expected lower <= upper)");
    }
  }
}

// The BGR colours in the configured residue range.
ColorRangeTable residue_colors(const Params& params) {
  const ColorSpace space = parse_color_space(params.string("color_space"));
  const auto lower = residue_bound(params, "residue_lower", info(space).residue_lower);
  const auto upper = residue_bound(params, "residue_upper", info(space).residue_upper);
  check_bounds_ordered(lower, upper, space);
  switch (space) {
    case ColorSpace::kHsv:
      return ColorRangeTable(cv::COLOR_BGR2HSV, lower, upper);
    case ColorSpace::kLab:
      return ColorRangeTable(cv::COLOR_BGR2Lab, lower, upper);
    case ColorSpace::kBgr:
      break;
  }
  return ColorRangeTable(-1, lower, upper);
}

// Per-thread working masks: the stage runs frames concurrently, and these keep their
// buffers from one frame to the next on the same thread.
struct Scratch {
  BitMask residue;    // trusted colour in the residue range; then despeckled and dilated
  BitMask untrusted;  // colour not kValid, or darker than min_value
  std::vector<std::uint8_t> dark;  // one row: 255 where every channel is below min_value
};

class ColorThreshold final : public Transform {
 public:
  explicit ColorThreshold(const StageContext& context)
      : residue_colors_(residue_colors(context.params)),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        output_(context.params) {}

  void process(Frame& frame) override {
    const auto& color = frame.input<RegisteredColor>(kColorInput);
    const auto& depth = frame.input<DepthImage>(kDepthInput);
    check_residue_inputs(color, depth);
    const cv::Rect area = output_.area(depth.mm.size());
    thread_local Scratch scratch;
    const cv::Mat bgr = color.bgr(area);
    const cv::Mat status = color.status(area);
    min_value_ > 0 ? classify<true>(bgr, status, scratch) : classify<false>(bgr, status, scratch);
    // Pixels without depth are unknown too: emit finds them as it writes the soil depth.
    output_.emit(frame, area, scratch.residue, scratch.untrusted, depth.mm(area));
  }

 private:
  // Marks, per pixel, residue (a trusted colour in the range) and untrusted. An untrusted
  // colour may fall in the range by chance (an occluded pixel carries the colour of what
  // hides it); it must not grow into its neighbours.
  template <bool kCheckDark>
  void classify(const cv::Mat& bgr_image, const cv::Mat& status_image, Scratch& scratch) const {
    const int rows = bgr_image.rows;
    const int cols = bgr_image.cols;
    scratch.residue.resize(rows, cols);
    scratch.untrusted.resize(rows, cols);
    scratch.dark.resize(kCheckDark ? static_cast<std::size_t>(cols) : 0);
    std::uint8_t* const dark = scratch.dark.data();
    for (int y = 0; y < rows; ++y) {
      const auto* bgr = bgr_image.ptr<std::uint8_t>(y);
      std::uint64_t* residue = scratch.residue.row(y);
      residue_colors_.classify_row(kernels_, bgr, cols, residue);
      if constexpr (kCheckDark) {
        for (int x = 0; x < cols; ++x) {
          const std::uint8_t* pixel = bgr + 3 * x;
          dark[x] = std::max({pixel[0], pixel[1], pixel[2]}) < min_value_ ? 255 : 0;
        }
      }
      const auto* status = status_image.ptr<std::uint8_t>(y);
      std::uint64_t* untrusted = scratch.untrusted.row(y);
      for (int x = 0; x < cols; x += 64) {
        const int count = std::min(64, cols - x);
        const std::uint64_t dark_bits = kCheckDark ? marked_bits(dark + x, count) : 0;
        const std::uint64_t trusted = valid_status_bits(status + x, count) & ~dark_bits;
        const std::uint64_t pixels =
            count == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << count) - 1;
        residue[x / 64] &= trusted;
        untrusted[x / 64] = ~trusted & pixels;
      }
    }
  }

  const ResidueKernels& kernels_ = *available_residue_kernels().front();
  const ColorRangeTable residue_colors_;
  const int min_value_;
  ResidueOutput output_;
};

}  // namespace

StageDescriptor describe_color_threshold() {
  StageDescriptor d;
  d.type = "segmentation.color_threshold";
  d.summary = "residue mask from a colour range, dilated; soil depth = depth outside it";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {
      ParamSpec::choice("color_space", {"hsv", "lab", "bgr"}, "hsv")
          .describe("colour space of the residue range (OpenCV 8-bit: H 0-180, Lab 0-255)"),
      ParamSpec::json("residue_lower", nullptr)
          .describe("lowest residue colour [c0, c1, c2], inclusive; null = hsv [18, 40, 50], "
                    "lab [50, 110, 140], bgr [0, 140, 160]"),
      ParamSpec::json("residue_upper", nullptr)
          .describe("highest residue colour [c0, c1, c2], inclusive; null = hsv [40, 255, 255], "
                    "lab [255, 132, 255], bgr [255, 255, 255]"),
      dilation_px_param(),
      segmented_roi_param(),
      speckle_px_param(0),
      min_value_param(),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<ColorThreshold>();
  return d;
}

TILTH_STAGE(describe_color_threshold());

}  // namespace tilth::segmentation
