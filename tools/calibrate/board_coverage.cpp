#include "board_coverage.h"

#include <algorithm>
#include <array>

namespace tilth::calibrate {
namespace {

// The nine areas a user is asked to cover, as ranges of grid cells: the corners are the
// outer 2x2 cells, the edges the cells between them, the middle what is left.
struct Area {
  const char* name;
  int first_column, last_column, first_row, last_row;
};

constexpr int kC = BoardCoverage::kColumns;
constexpr int kR = BoardCoverage::kRows;
constexpr std::array<Area, 9> kAreas{{
    {"top left", 0, 1, 0, 1},
    {"top edge", 2, kC - 3, 0, 1},
    {"top right", kC - 2, kC - 1, 0, 1},
    {"left edge", 0, 1, 2, kR - 3},
    {"middle", 2, kC - 3, 2, kR - 3},
    {"right edge", kC - 2, kC - 1, 2, kR - 3},
    {"bottom left", 0, 1, kR - 2, kR - 1},
    {"bottom edge", 2, kC - 3, kR - 2, kR - 1},
    {"bottom right", kC - 2, kC - 1, kR - 2, kR - 1},
}};

}  // namespace

BoardCoverage::BoardCoverage(cv::Size image)
    : image_(image), cells_(kRows, std::string(kColumns, '.')) {}

void BoardCoverage::add(const std::vector<cv::Point2f>& corners) {
  for (const auto& corner : corners) {
    const int column = static_cast<int>((corner.x + 0.5) * kColumns / image_.width);
    const int row = static_cast<int>((corner.y + 0.5) * kRows / image_.height);
    if (column >= 0 && column < kColumns && row >= 0 && row < kRows) cells_[row][column] = '#';
  }
}

double BoardCoverage::covered_fraction() const {
  int covered = 0;
  for (const auto& row : cells_)
    covered += static_cast<int>(std::count(row.begin(), row.end(), '#'));
  return static_cast<double>(covered) / (kColumns * kRows);
}

std::string BoardCoverage::missing_areas() const {
  std::string missing;
  for (const auto& area : kAreas) {
    bool reached = false;
    for (int row = area.first_row; row <= area.last_row; ++row) {
      for (int column = area.first_column; column <= area.last_column; ++column) {
        reached = reached || cells_[row][column] == '#';
      }
    }
    if (!reached) missing += (missing.empty() ? "" : ", ") + std::string(area.name);
  }
  return missing;
}

}  // namespace tilth::calibrate
