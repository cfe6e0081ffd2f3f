// Which parts of a camera's image the board's corners have reached: a coarse grid whose
// uncovered cells leave the lens model unchecked there. The solve report shows it for
// the views used, `tilth calibrate capture` for the views kept so far.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

namespace tilth::calibrate {

class BoardCoverage {
 public:
  static constexpr int kColumns = 8;
  static constexpr int kRows = 6;

  explicit BoardCoverage(cv::Size image);

  void add(const std::vector<cv::Point2f>& corners);

  // Rows of '#' (a corner fell in the cell) and '.' (none), top row first.
  const std::vector<std::string>& cells() const { return cells_; }
  double covered_fraction() const;
  // The image's corners, edges and middle the board has not reached yet ("top left,
  // bottom edge"); empty when it reached them all.
  std::string missing_areas() const;

 private:
  cv::Size image_;
  std::vector<std::string> cells_;
};

}  // namespace tilth::calibrate
