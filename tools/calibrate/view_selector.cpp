#include "view_selector.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace tilth::calibrate {
namespace {

double largest_move(const std::vector<cv::Point2f>& before, const std::vector<cv::Point2f>& now) {
  double largest = 0.0;
  for (std::size_t i = 0; i < now.size(); ++i) {
    largest = std::max(largest, static_cast<double>(cv::norm(now[i] - before[i])));
  }
  return largest;
}

double difference(const BoardPlacement& a, const BoardPlacement& b) {
  return std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.size - b.size) +
         std::abs(a.skew - b.skew);
}

std::string describe(const BoardPlacement& placement) {
  std::ostringstream text;
  text.precision(2);
  text << std::fixed << "x " << placement.x << ", y " << placement.y << ", size " << placement.size
       << ", skew " << placement.skew;
  return text.str();
}

}  // namespace

BoardPlacement placement_of(const std::vector<cv::Point2f>& corners, cv::Size inner_corners,
                            cv::Size image) {
  const cv::Point2d up_left = corners.front();
  const cv::Point2d up_right = corners[inner_corners.width - 1];
  const cv::Point2d down_right = corners.back();
  const cv::Point2d down_left = corners[corners.size() - inner_corners.width];
  // The outer corners' quadrilateral, by its diagonals.
  const cv::Point2d diagonal_a = down_right - up_left;
  const cv::Point2d diagonal_b = down_left - up_right;
  const double area = std::abs(diagonal_a.cross(diagonal_b)) / 2.0;
  const double border = std::sqrt(area);
  cv::Point2d mean;
  for (const auto& corner : corners) mean += cv::Point2d(corner);
  mean /= static_cast<double>(corners.size());

  BoardPlacement placement;
  placement.x = std::clamp((mean.x - border / 2.0) / (image.width - border), 0.0, 1.0);
  placement.y = std::clamp((mean.y - border / 2.0) / (image.height - border), 0.0, 1.0);
  placement.size = std::sqrt(area / (static_cast<double>(image.width) * image.height));
  const cv::Point2d along = up_left - up_right;
  const cv::Point2d down = down_right - up_right;
  const double angle =
      std::acos(std::clamp(along.dot(down) / (cv::norm(along) * cv::norm(down)), -1.0, 1.0));
  placement.skew = std::min(1.0, 2.0 * std::abs(std::numbers::pi / 2.0 - angle));
  return placement;
}

ViewSelector::Decision ViewSelector::consider(BoardSighting sighting) {
  const auto expected = static_cast<std::size_t>(options_.inner_corners.area());
  if (sighting.depth.size() != expected || sighting.color.size() != expected) {
    previous_ = {};
    still_frames_ = 0;
    kept_this_stop_ = false;
    return {Verdict::kNoBoard,
            sighting.depth.size() == expected
                ? "board not found in the colour image"
                : (sighting.color.size() == expected ? "board not found in the ToF intensity"
                                                     : "board not found in either image")};
  }
  const bool compared = !previous_.color.empty();
  const double move = compared ? std::max(largest_move(previous_.depth, sighting.depth),
                                          largest_move(previous_.color, sighting.color))
                               : 0.0;
  previous_ = sighting;
  if (compared && move > options_.still_px) {
    still_frames_ = 1;
    kept_this_stop_ = false;
    std::ostringstream reason;
    reason.precision(1);
    reason << std::fixed << "board moving (" << move << " px since the last frame)";
    return {Verdict::kMoving, reason.str()};
  }
  ++still_frames_;
  if (still_frames_ < options_.still_frames) {
    return {Verdict::kSettling, "board still for " + std::to_string(still_frames_) + " of " +
                                    std::to_string(options_.still_frames) + " frames"};
  }
  if (kept_this_stop_) return {Verdict::kSeenBefore, "view kept already; move the board"};
  const BoardPlacement placement =
      placement_of(sighting.color, options_.inner_corners, options_.color_image);
  for (std::size_t i = 0; i < kept_.size(); ++i) {
    if (difference(placement, kept_[i]) <= options_.new_placement) {
      return {Verdict::kSeenBefore,
              "placed like view " + std::to_string(i) + " (" + describe(placement) + ")"};
    }
  }
  kept_.push_back(placement);
  kept_this_stop_ = true;
  return {Verdict::kKeep, describe(placement)};
}

}  // namespace tilth::calibrate
