#include "mask_import.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <memory>
#include <optional>

#include <opencv2/imgcodecs.hpp>

#include "framework/graph_session.h"
#include "image_folder/frames_csv.h"
#include "image_folder/image_file.h"
#include "image_folder/pixel_checks.h"
#include "image_folder/recording_json.h"
#include "label_map.h"
#include "labelled_mask.h"
#include "mask_registration.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::tools {
namespace {

namespace fs = std::filesystem;
using recording::FrameEntry;

// Where a tool's export keeps the masks: labelme2voc's SegmentationClassPNG/ (its
// SegmentationClass/ holds NumPy files), CVAT's SegmentationClass/, or the folder itself.
fs::path masks_folder(const fs::path& labels) {
  for (const char* below : {"SegmentationClassPNG", "SegmentationClass"}) {
    if (fs::is_directory(labels / below)) return labels / below;
  }
  return labels;
}

std::vector<fs::path> png_files(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (extension == ".png" && entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// "a, b, c and 4 more"
template <class Item, class Text>
std::string some_of(const std::vector<Item>& items, Text text) {
  constexpr std::size_t kShown = 5;
  std::string listed;
  for (std::size_t i = 0; i < std::min(items.size(), kShown); ++i) {
    listed += (i == 0 ? "" : ", ") + text(items[i]);
  }
  if (items.size() > kShown) listed += " and " + std::to_string(items.size() - kShown) + " more";
  return listed;
}

struct Match {
  fs::path file;
  const FrameEntry* frame;
};

// Each mask's frame: the one whose colour image has the mask's file stem.
std::vector<Match> match_frames(const std::vector<fs::path>& files,
                                const std::vector<FrameEntry>& frames, const fs::path& csv) {
  std::map<std::string, std::vector<const FrameEntry*>> by_stem;
  for (const FrameEntry& frame : frames) {
    by_stem[fs::path(frame.color).stem().string()].push_back(&frame);
  }
  std::vector<Match> matches;
  std::vector<fs::path> unmatched;
  for (const fs::path& file : files) {
    const auto found = by_stem.find(file.stem().string());
    if (found == by_stem.end()) {
      unmatched.push_back(file);
      continue;
    }
    if (found->second.size() > 1) {
      throw Error(file.string() + ": matches the colour images of frames.csv lines " +
                  std::to_string(found->second[0]->line) + " and " +
                  std::to_string(found->second[1]->line) + " (" + found->second[0]->color + ", " +
                  found->second[1]->color +
                  "); expected colour images whose file names tell the frames apart");
    }
    matches.push_back({file, found->second[0]});
  }
  if (!unmatched.empty()) {
    throw Error(std::to_string(unmatched.size()) + " of " + std::to_string(files.size()) +
                " masks match no frame: " +
                some_of(unmatched, [](const fs::path& file) { return file.string(); }) +
                " (expected the file name of a colour image in " + csv.string() + ", e.g. " +
                fs::path(frames.empty() ? "000000.png" : frames[0].color).stem().string() +
                ".png for " + (frames.empty() ? "color/000000.png" : frames[0].color) + ")");
  }
  std::sort(matches.begin(), matches.end(),
            [](const Match& a, const Match& b) { return a.frame->line < b.frame->line; });
  return matches;
}

std::string new_mask_path(const FrameEntry& frame) {
  return "mask/" + recording::frame_file_name(frame.index);
}

// Without --overwrite, no matched frame may have a mask: named in frames.csv, or a file
// where the new one would go.
void check_no_masks(const fs::path& folder, const std::vector<Match>& matches,
                    const fs::path& csv) {
  std::vector<std::string> existing;
  for (const Match& match : matches) {
    const FrameEntry& frame = *match.frame;
    if (!frame.mask.empty()) {
      existing.push_back("frame " + std::to_string(frame.index) + " (line " +
                         std::to_string(frame.line) + ": " + frame.mask + ")");
    } else if (fs::exists(folder / new_mask_path(frame))) {
      existing.push_back("frame " + std::to_string(frame.index) + " (" + new_mask_path(frame) +
                         " exists)");
    }
  }
  if (existing.empty()) return;
  throw Error(csv.string() + ": " + std::to_string(existing.size()) +
              " of the frames to import have a mask already: " +
              some_of(existing, [](const std::string& text) { return text; }) +
              "; --overwrite replaces them");
}

// The masks written so far under temporary names, removed unless they are committed,
// with the mask folder when it was made for them.
class PendingMasks {
 public:
  explicit PendingMasks(fs::path folder)
      : folder_(std::move(folder)), made_folder_(fs::create_directories(folder_)) {}

  ~PendingMasks() {
    std::error_code ignored;
    for (const auto& [temporary, final] : files_) fs::remove(temporary, ignored);
    if (!committed_ && made_folder_ && fs::is_empty(folder_, ignored)) {
      fs::remove(folder_, ignored);
    }
  }

  void write(const fs::path& file, const cv::Mat& mask) {
    std::vector<std::uint8_t> png;
    if (!cv::imencode(".png", mask, png)) throw Error(file.string() + ": cannot encode PNG");
    fs::path temporary = file;
    temporary += ".new";
    files_.emplace_back(temporary, file);
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
    out.close();
    if (!out) throw Error(temporary.string() + ": cannot write");
  }

  void commit() {
    for (const auto& [temporary, final] : files_) fs::rename(temporary, final);
    files_.clear();
    committed_ = true;
  }

 private:
  const fs::path folder_;
  const bool made_folder_;
  bool committed_ = false;
  std::vector<std::pair<fs::path, fs::path>> files_;
};

void count_classes(const cv::Mat& mask, MaskImportResult& result) {
  const int residue = cv::countNonZero(mask == ResidueMask::kResidue);
  const int soil = cv::countNonZero(mask == ResidueMask::kSoil);
  result.residue += static_cast<std::uint64_t>(residue);
  result.soil += static_cast<std::uint64_t>(soil);
  result.unknown += static_cast<std::uint64_t>(mask.total()) - residue - soil;
}

}  // namespace

MaskImportResult import_masks(const MaskImportOptions& options) {
  const fs::path& folder = options.recording;
  if (!fs::exists(folder)) {
    throw Error(folder.string() + ": no such folder (expected an image-folder recording)");
  }
  if (!fs::is_directory(folder)) {
    throw Error(folder.string() +
                ": is a file; masks are imported into an image-folder recording (an MCAP "
                "recording: `tilth recording export " +
                folder.string() + " DIR` first, then import into DIR)");
  }
  const recording::RecordingJson recording = recording::read_recording_json(folder);
  const fs::path csv = folder / "frames.csv";
  const std::vector<FrameEntry> frames = recording::read_frames_csv(csv);

  if (!fs::is_directory(options.labels)) {
    throw Error(options.labels.string() +
                ": no such folder (expected a labelling tool's export: label names and masks)");
  }
  LabelMap labels = read_label_map(options.labels);
  assign_classes(labels, options.residue, options.soil);

  MaskImportResult result;
  result.masks = masks_folder(options.labels);
  const std::vector<fs::path> files = png_files(result.masks);
  if (files.empty()) {
    throw Error(result.masks.string() + ": holds no PNG masks (expected one per labelled frame)");
  }
  const std::vector<Match> matches = match_frames(files, frames, csv);
  if (!options.overwrite) check_no_masks(folder, matches, csv);

  const RigCalibration& rig = recording.calibration;
  const cv::Size size = options.depth_grid ? cv::Size(rig.depth.width, rig.depth.height)
                                           : cv::Size(rig.color.width, rig.color.height);
  const std::string size_origin = options.depth_grid
                                      ? "the depth images', depth_camera in the calibration"
                                      : "the colour images', color_camera in the calibration";
  const auto shared_rig = std::make_shared<const RigCalibration>(rig);
  std::unique_ptr<StageRegistry> registry;
  std::optional<MaskRegistration> registration;
  if (!options.depth_grid) {
    registry = load_plugins(".");
    registration.emplace(*registry);
  }

  PendingMasks pending(folder / "mask");
  std::map<std::size_t, std::string> mask_by_line;
  for (const Match& match : matches) {
    const FrameEntry& frame = *match.frame;
    const cv::Mat classes = read_labelled_mask(match.file, labels, size, size_origin);
    cv::Mat mask = classes;
    if (registration) {
      const fs::path depth_file = folder / frame.depth;
      const std::string where = depth_file.string() + " (" + csv.filename().string() + " line " +
                                std::to_string(frame.line) + ")";
      cv::Mat depth;
      try {
        depth = recording::read_image_file(depth_file);
      } catch (const Error& error) {
        const std::string prefix = depth_file.string() + ": ";
        const std::string text = error.what();
        throw Error(where + ": " + (text.starts_with(prefix) ? text.substr(prefix.size()) : text));
      }
      const std::string mismatch =
          recording::pixel_mismatch(depth, CV_16UC1, cv::Size(rig.depth.width, rig.depth.height),
                                    "depth_camera in the calibration");
      if (!mismatch.empty()) throw Error(where + ": " + mismatch);
      mask = registration->to_depth_grid(depth, shared_rig, classes, frame.index);
    }
    pending.write(folder / new_mask_path(frame), mask);
    mask_by_line[frame.line] = new_mask_path(frame);
    count_classes(mask, result);
  }
  pending.commit();
  recording::rewrite_mask_column(csv, mask_by_line);

  result.imported = matches.size();
  for (const FrameEntry& frame : frames) {
    if (mask_by_line.count(frame.line) == 0) result.without_mask.push_back(frame.index);
  }
  return result;
}

}  // namespace tilth::tools
