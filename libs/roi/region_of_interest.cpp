#include "roi/region_of_interest.h"

#include <algorithm>
#include <array>

#include "tilth/error.h"

namespace tilth {
namespace {

constexpr std::array<const char*, 4> kFields = {"x", "y", "width", "height"};

[[noreturn]] void roi_error(const std::string& problem) {
  throw Error("parameter 'roi': " + problem);
}

std::string size_text(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

std::string rect_text(const cv::Rect& rect) {
  return "x " + std::to_string(rect.x) + ", y " + std::to_string(rect.y) + ", " +
         size_text(rect.size());
}

cv::Rect parse_rect(const nlohmann::json& value) {
  for (const auto& [name, field] : value.items()) {
    if (std::find(kFields.begin(), kFields.end(), name) == kFields.end()) {
      roi_error("no field \"" + name + "\" (expected x, y, width, height)");
    }
  }
  std::array<int, 4> numbers{};
  for (std::size_t i = 0; i < kFields.size(); ++i) {
    const std::string name = kFields[i];
    if (!value.contains(name)) roi_error("missing field \"" + name + "\"");
    const nlohmann::json& field = value.at(name);
    if (!field.is_number_integer()) {
      roi_error("\"" + name + "\" must be an integer number of pixels, got " + field.dump());
    }
    numbers[i] = field.get<int>();
  }
  const cv::Rect rect(numbers[0], numbers[1], numbers[2], numbers[3]);
  if (rect.width < 1) roi_error("\"width\" must be >= 1 px, got " + std::to_string(rect.width));
  if (rect.height < 1) roi_error("\"height\" must be >= 1 px, got " + std::to_string(rect.height));
  return rect;
}

}  // namespace

RegionOfInterest::RegionOfInterest(const nlohmann::json& value, Whole when_null)
    : whole_(when_null) {
  if (value.is_null()) return;
  if (value == "image") {
    whole_ = Whole::kImage;
  } else if (value == "middle_half") {
    whole_ = Whole::kMiddleHalf;
  } else if (value.is_object()) {
    pixels_ = parse_rect(value);
  } else {
    roi_error(
        "expected null, \"image\", \"middle_half\" or {\"x\", \"y\", \"width\", \"height\"} in "
        "pixels, got " +
        value.dump());
  }
}

cv::Rect RegionOfInterest::unclipped_on(cv::Size image) const {
  if (pixels_) return *pixels_;
  if (whole_ == Whole::kImage) return {{0, 0}, image};
  const cv::Size half(std::max(1, image.width / 2), std::max(1, image.height / 2));
  return {(image.width - half.width) / 2, (image.height - half.height) / 2, half.width,
          half.height};
}

cv::Rect RegionOfInterest::on(cv::Size image) const {
  const cv::Rect wanted = unclipped_on(image);
  const cv::Rect region = wanted & cv::Rect({0, 0}, image);
  if (region.empty()) {
    roi_error(rect_text(wanted) + " lies outside the " + size_text(image) + " depth image");
  }
  return region;
}

cv::Rect RegionOfInterest::around(cv::Size image, int margin_px) const {
  const cv::Rect region = on(image);
  const cv::Rect grown(region.x - margin_px, region.y - margin_px, region.width + 2 * margin_px,
                       region.height + 2 * margin_px);
  return grown & cv::Rect({0, 0}, image);
}

bool RegionOfInterest::clipped_on(cv::Size image) const { return on(image) != unclipped_on(image); }

std::string RegionOfInterest::clipping_note(cv::Size image) const {
  return "roi " + rect_text(unclipped_on(image)) + " reaches outside the " + size_text(image) +
         " image; using " + rect_text(on(image));
}

ParamSpec roi_param(RegionOfInterest::Whole when_null) {
  return ParamSpec::json("roi", nullptr)
      .in_unit("px")
      .describe(std::string("region of interest {\"x\", \"y\", \"width\", \"height\"}, clipped "
                            "to the image, \"middle_half\" or \"image\"; null = ") +
                (when_null == RegionOfInterest::Whole::kImage
                     ? "the whole image"
                     : "the middle half in each direction"));
}

}  // namespace tilth
