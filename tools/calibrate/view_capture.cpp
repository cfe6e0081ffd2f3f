#include "view_capture.h"

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "board_views.h"
#include "tilth/error.h"

namespace tilth::calibrate {
namespace {

namespace fs = std::filesystem;

// The quick board search takes about 50 ms at this width; a larger colour image is
// searched at an integer fraction of its size.
constexpr int kSearchWidth = 640;

std::vector<cv::Point2f> color_corners(const cv::Mat& color, cv::Size inner_corners) {
  cv::Mat gray = color;
  if (color.channels() == 3) cv::cvtColor(color, gray, cv::COLOR_BGR2GRAY);
  const int factor =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(color.cols) / kSearchWidth)));
  if (factor == 1) return board_corners(gray, inner_corners, BoardSearch::kQuick);
  cv::Mat small;
  cv::resize(gray, small, cv::Size(gray.cols / factor, gray.rows / factor), 0, 0, cv::INTER_AREA);
  auto corners = board_corners(small, inner_corners, BoardSearch::kQuick);
  // A pixel of the small image covers `factor` pixels of the large one.
  for (auto& corner : corners)
    corner = (corner + cv::Point2f(0.5f, 0.5f)) * factor - cv::Point2f(0.5f, 0.5f);
  return corners;
}

void refuse_existing_views(const fs::path& folder) {
  if (!fs::exists(folder)) return;
  if (!fs::is_directory(folder)) {
    throw Error(folder.string() + ": exists and is not a folder; expected a folder for the views");
  }
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.ends_with("_intensity.png") || name.ends_with("_color.png")) {
      throw Error(folder.string() + ": holds views already (" + name +
                  "); give a new folder, and solve both together");
    }
  }
}

void write_image(const fs::path& file, const cv::Mat& image) {
  // cv::imwrite picks the format by the extension, so the temporary name keeps it.
  const fs::path temporary = file.parent_path() / (".partial-" + file.filename().string());
  bool written = false;
  try {
    written = cv::imwrite(temporary.string(), image);
  } catch (const cv::Exception& error) {
    fs::remove(temporary);
    throw Error(file.string() + ": cannot write it: " + error.what());
  }
  if (!written) {
    fs::remove(temporary);
    throw Error(file.string() + ": cannot write it (a full disk, or no permission?)");
  }
  fs::rename(temporary, file);
}

std::string view_name(std::size_t index) {
  std::ostringstream name;
  name << std::setw(3) << std::setfill('0') << index;
  return name.str();
}

// What the user still has to reach with the board.
std::string not_reached(const BoardCoverage& color, const BoardCoverage& depth) {
  const std::string in_color = color.missing_areas();
  const std::string in_depth = depth.missing_areas();
  if (in_color.empty() && in_depth.empty()) return "both images covered everywhere";
  std::string text = "not reached yet:";
  if (!in_color.empty()) text += " colour image: " + in_color + (in_depth.empty() ? "" : ";");
  if (!in_depth.empty()) text += " ToF image: " + in_depth;
  return text;
}

}  // namespace

CaptureResult capture_views(const PairStream& stream, CaptureOptions options,
                            std::ostream& progress) {
  refuse_existing_views(options.out);
  CaptureResult result;
  std::optional<ViewSelector> selector;
  std::optional<ViewSelector::Verdict> last_verdict;

  const auto on_pair = [&](const FramePair& pair) {
    if (!selector) {
      options.selection.color_image = pair.color.size();
      selector.emplace(options.selection);
      result.depth_coverage.emplace(pair.intensity.size());
      result.color_coverage.emplace(pair.color.size());
    }
    ++result.pairs;
    BoardSighting sighting;
    sighting.depth = board_corners(intensity_to_8bit(pair.intensity),
                                   options.selection.inner_corners, BoardSearch::kQuick);
    sighting.color = color_corners(pair.color, options.selection.inner_corners);
    result.board_pairs += !sighting.depth.empty() && !sighting.color.empty();
    const BoardSighting seen = sighting;
    const ViewSelector::Decision decision = selector->consider(std::move(sighting));
    if (decision.verdict != ViewSelector::Verdict::kKeep) {
      if (decision.verdict != last_verdict) {
        progress << "frame " << pair.frame_id << ": " << decision.reason << "\n" << std::flush;
      }
      last_verdict = decision.verdict;
      return true;
    }
    last_verdict = decision.verdict;
    const std::string name = view_name(result.kept);
    fs::create_directories(options.out);
    write_image(options.out / (name + "_intensity.png"), pair.intensity);
    write_image(options.out / (name + "_color.png"), pair.color);
    ++result.kept;
    result.depth_coverage->add(seen.depth);
    result.color_coverage->add(seen.color);
    progress << "view " << name << " kept (frame " << pair.frame_id << "; " << decision.reason
             << "); " << not_reached(*result.color_coverage, *result.depth_coverage) << "\n"
             << std::flush;
    return result.kept < options.views;
  };
  result.stopped = look_at_pairs(stream, on_pair).stopped && result.kept < options.views;
  return result;
}

}  // namespace tilth::calibrate
