#include "overlays.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

#include <opencv2/imgcodecs.hpp>

#include "data_uri.h"

namespace tilth::ab {
namespace {

namespace fs = std::filesystem;

// BGR; blended half and half over the colour, except residue called soil, which is
// painted over it: it reaches the soil depth and so the distance, the costliest mistake.
struct Tint {
  cv::Vec3b bgr;
  bool opaque = false;
};
const Tint kAgreedResidue{{0, 220, 255}};        // yellow: residue called residue
const Tint kFalseResidue{{40, 40, 230}};         // red: soil called residue
const Tint kMissedResidue{{255, 0, 255}, true};  // magenta: residue left in the soil depth
const Tint kUnknown{{160, 160, 160}};            // grey: called unknown / truth unknown
constexpr std::uint8_t kResidue = 255;
constexpr std::uint8_t kUnknownValue = 128;
constexpr int kJpegQuality = 92;

struct Disagreement {
  std::uint64_t frame_id = 0;
  std::size_t valid = 0;
  std::size_t reported = 0;  // variants with this frame
  double spread_mm = 0.0;
  double max_abs_error_mm = 0.0;

  bool validity_differs() const { return valid > 0 && valid < reported; }
  auto rank() const { return std::make_tuple(validity_differs(), spread_mm, max_abs_error_mm); }
};

std::string frame_file(std::uint64_t frame_id, const char* extension) {
  char name[40];
  std::snprintf(name, sizeof name, "%06llu.%s", static_cast<unsigned long long>(frame_id),
                extension);
  return name;
}

cv::Mat read_image(const fs::path& file, int flags) {
  std::error_code error;
  if (!fs::is_regular_file(file, error)) return {};
  return cv::imread(file.string(), flags);
}

const Tint* truth_tint(std::uint8_t truth) {
  if (truth == kResidue) return &kAgreedResidue;
  return truth == kUnknownValue ? &kUnknown : nullptr;
}

// Judged against the truth when there is one; pixels of unknown truth are not judged.
const Tint* mask_tint(std::uint8_t called, const std::uint8_t* truth) {
  if (called == kUnknownValue) return &kUnknown;
  const bool residue = called == kResidue;
  if (truth == nullptr) return residue ? &kAgreedResidue : nullptr;
  if (*truth == kUnknownValue) return nullptr;
  const bool truly_residue = *truth == kResidue;
  if (residue) return truly_residue ? &kAgreedResidue : &kFalseResidue;
  return truly_residue ? &kMissedResidue : nullptr;
}

// `tint_of(i)` for pixel i (row-major): a tint, or none.
template <class TintOf>
cv::Mat tinted(const cv::Mat& base, TintOf tint_of) {
  cv::Mat out = base.clone();
  for (int y = 0; y < out.rows; ++y) {
    auto* row = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < out.cols; ++x) {
      const Tint* tint = tint_of(static_cast<std::size_t>(y) * out.cols + x);
      if (tint == nullptr) continue;
      if (tint->opaque) {
        row[x] = tint->bgr;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        row[x][c] = static_cast<std::uint8_t>((row[x][c] + tint->bgr[c]) / 2);
      }
    }
  }
  return out;
}

// At full resolution: the report shows it small and zooms in on a click.
std::string panel_uri(const cv::Mat& image) { return jpeg_data_uri(image, kJpegQuality); }

std::string describe(const Disagreement& d) {
  char text[160];
  if (d.validity_differs()) {
    std::snprintf(text, sizeof text, "valid in %zu of %zu variants", d.valid, d.reported);
  } else if (d.spread_mm > 0.0) {
    std::snprintf(text, sizeof text, "distances %.3f mm apart", d.spread_mm);
  } else {
    std::snprintf(text, sizeof text, "largest |error| %.3f mm", d.max_abs_error_mm);
  }
  return text;
}

std::vector<Disagreement> ranked_disagreements(const Comparison& comparison,
                                               std::size_t recording) {
  std::map<std::uint64_t, Disagreement> by_frame;
  std::map<std::uint64_t, std::pair<double, double>> valid_range;
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    for (const auto& frame : comparison.job(v, recording).frames) {
      Disagreement& d = by_frame[frame.record.frame_id];
      d.frame_id = frame.record.frame_id;
      ++d.reported;
      if (frame.error_mm) {
        d.max_abs_error_mm = std::max(d.max_abs_error_mm, std::abs(*frame.error_mm));
      }
      if (!frame.record.valid || !frame.record.distance_mm) continue;
      ++d.valid;
      const double distance = *frame.record.distance_mm;
      auto [range, first] = valid_range.try_emplace(d.frame_id, distance, distance);
      range->second.first = std::min(range->second.first, distance);
      range->second.second = std::max(range->second.second, distance);
    }
  }
  std::vector<Disagreement> ranked;
  for (auto& [frame_id, d] : by_frame) {
    if (const auto range = valid_range.find(frame_id); range != valid_range.end()) {
      d.spread_mm = range->second.second - range->second.first;
    }
    ranked.push_back(d);
  }
  // by_frame is in frame order, and the sort keeps it among equals.
  std::stable_sort(ranked.begin(), ranked.end(), [](const Disagreement& a, const Disagreement& b) {
    return a.rank() > b.rank();
  });
  return ranked;
}

OverlayFrame overlay_frame(const Comparison& comparison, std::size_t recording,
                           const Disagreement& disagreement) {
  const auto images = [&](std::size_t variant) {
    return comparison.job(variant, recording).images;
  };
  const std::uint64_t id = disagreement.frame_id;
  OverlayFrame frame{id, describe(disagreement), {}};
  cv::Mat color = read_image(images(0) / "color" / frame_file(id, "jpg"), cv::IMREAD_COLOR);
  cv::Mat truth;
  for (std::size_t v = 0; v < comparison.variants.size() && truth.empty(); ++v) {
    truth = read_image(images(v) / "truth" / frame_file(id, "png"), cv::IMREAD_GRAYSCALE);
  }
  cv::Mat first_mask = read_image(images(0) / "mask" / frame_file(id, "png"), cv::IMREAD_GRAYSCALE);
  const cv::Size size = !truth.empty() ? truth.size() : first_mask.size();
  if (color.empty() || color.size() != size) {
    frame.panels.push_back({"colour: none", ""});
    color = cv::Mat(size.empty() ? cv::Size(1, 1) : size, CV_8UC3, cv::Scalar(110, 110, 110));
  } else {
    frame.panels.push_back({"colour", panel_uri(color)});
  }
  if (!truth.empty() && truth.size() != color.size()) truth.release();
  if (truth.empty()) {
    frame.panels.push_back({"truth: none", ""});
  } else {
    frame.panels.push_back({"truth", panel_uri(tinted(color, [&](std::size_t i) {
                              return truth_tint(truth.data[i]);
                            }))});
  }
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    const std::string& name = comparison.variants[v].name;
    const cv::Mat mask =
        read_image(images(v) / "mask" / frame_file(id, "png"), cv::IMREAD_GRAYSCALE);
    if (mask.empty() || mask.size() != color.size()) {
      frame.panels.push_back({name + ": no mask", ""});
      continue;
    }
    std::size_t missed = 0;
    const cv::Mat panel = tinted(color, [&](std::size_t i) {
      const Tint* tint = mask_tint(mask.data[i], truth.empty() ? nullptr : &truth.data[i]);
      missed += tint == &kMissedResidue ? 1 : 0;
      return tint;
    });
    frame.panels.push_back(
        {truth.empty() ? name : name + ": " + std::to_string(missed) + " px residue called soil",
         panel_uri(panel)});
  }
  return frame;
}

}  // namespace

std::vector<OverlayFrame> disagreement_overlays(const Comparison& comparison, std::size_t recording,
                                                std::size_t count) {
  std::vector<OverlayFrame> frames;
  const auto ranked = ranked_disagreements(comparison, recording);
  for (std::size_t i = 0; i < std::min(count, ranked.size()); ++i) {
    frames.push_back(overlay_frame(comparison, recording, ranked[i]));
  }
  return frames;
}

}  // namespace tilth::ab
