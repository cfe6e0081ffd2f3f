// Which frames of a camera pair's stream become calibration views: the board found in
// both images, held still (the two cameras expose at different moments, so a board on
// the move is a different pose in each), and in a pose unlike every view kept so far.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

namespace tilth::calibrate {

// The board's inner corners in one frame pair, in each image's own pixels; empty where
// the board was not found.
struct BoardSighting {
  std::vector<cv::Point2f> depth;
  std::vector<cv::Point2f> color;
};

// Where the board lies in the colour image, each 0 to 1, as ROS's camera_calibration
// measures it: x and y of its middle within the room it has to move, its size (the root of
// its area over the image's), its skew (how far the angle at its first corner is from a
// right angle, doubled, in radians).
struct BoardPlacement {
  double x = 0.0;
  double y = 0.0;
  double size = 0.0;
  double skew = 0.0;
};

// `corners` of a board of `inner_corners` (columns x rows) in an image of `image` pixels.
BoardPlacement placement_of(const std::vector<cv::Point2f>& corners, cv::Size inner_corners,
                            cv::Size image);

struct SelectorOptions {
  cv::Size inner_corners{8, 5};
  cv::Size color_image;
  // No corner moved farther than this between consecutive frames, in either image's pixels,
  // for `still_frames` frames in a row.
  double still_px = 1.0;
  int still_frames = 3;
  // A view is new when its placement differs from every kept view's by more than this,
  // summed over x, y, size and skew (ROS camera_calibration's 0.2).
  double new_placement = 0.2;
};

class ViewSelector {
 public:
  enum class Verdict { kNoBoard, kMoving, kSettling, kSeenBefore, kKeep };
  struct Decision {
    Verdict verdict;
    std::string reason;  // for kKeep: the placement
  };

  explicit ViewSelector(SelectorOptions options) : options_(std::move(options)) {}

  // The next frame pair's sighting. kKeep means the caller keeps this pair as a view; it
  // then counts as kept.
  Decision consider(BoardSighting sighting);

  const std::vector<BoardPlacement>& kept() const { return kept_; }

 private:
  const SelectorOptions options_;
  BoardSighting previous_;
  int still_frames_ = 0;
  bool kept_this_stop_ = false;  // the board has not moved since the last kept view
  std::vector<BoardPlacement> kept_;
};

}  // namespace tilth::calibrate
