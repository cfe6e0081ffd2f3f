// sinks.evaluation: one JSON line per frame comparing the measurement with the ground
// truth, for offline evaluation (`tilth ab`, docs/ab-testing.md).
//
//   distance (GroundDistance) ──┐
//   truth    (GroundTruth)    ──┼──► {"frame_id": 3, "distance_mm": 517.9, "valid": true,
//   mask     (ResidueMask)    ──┤     "truth_mm": 518.0, "truth_soil_fraction": 0.41,
//   color    (RegisteredColor)──┘     "mask": {"tp": .., "fp": .., "fn": .., "tn": .., ...}}
//
// Every input is optional and an empty one is data too: a frame on which the chain
// produced no distance is written with "measured": false, so a missing measurement is
// counted against the chain rather than lost. Mask counts take residue (255) as the
// positive class over the pixels whose truth is known (0 or 255); a predicted 128
// (unknown) counts as not residue and is also counted on its own.
//
//   "evaluate": {"type": "sinks.evaluation",
//                "params": {"path": "frames.jsonl", "save_images": true}}
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "tilth/messages/ground_distance.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/plugin.h"

namespace tilth::sinks {
namespace {

using json = nlohmann::ordered_json;

std::string describe_mat(const cv::Mat& mat) {
  return std::to_string(mat.cols) + "x" + std::to_string(mat.rows) + " " +
         std::to_string(mat.channels()) + "-channel depth " + std::to_string(mat.depth());
}

// The confusion counts over the pixels the stage segmented; "ignored" counts those
// outside them and those whose truth is mixed.
json mask_counts(const ResidueMask& mask, const cv::Mat& truth) {
  const cv::Mat& predicted = mask.values;
  if (predicted.type() != CV_8UC1 || truth.type() != CV_8UC1 || predicted.size != truth.size) {
    throw Error("mask: expected an 8-bit 1-channel mask of the truth mask's size (" +
                describe_mat(truth) + "), got " + describe_mat(predicted));
  }
  const cv::Rect image({0, 0}, truth.size());
  const cv::Rect segmented = mask.segmented.empty() ? image : mask.segmented & image;
  std::int64_t tp = 0, fp = 0, fn = 0, tn = 0, unknown = 0;
  for (int y = segmented.y; y < segmented.y + segmented.height; ++y) {
    const auto* known = truth.ptr<std::uint8_t>(y);
    const auto* called = predicted.ptr<std::uint8_t>(y);
    for (int x = segmented.x; x < segmented.x + segmented.width; ++x) {
      const bool truth_residue = known[x] == ResidueMask::kResidue;
      if (!truth_residue && known[x] != ResidueMask::kSoil) continue;
      const bool called_residue = called[x] == ResidueMask::kResidue;
      if (called[x] == ResidueMask::kUnknown) ++unknown;
      if (called_residue) {
        ++(truth_residue ? tp : fp);
      } else {
        ++(truth_residue ? fn : tn);
      }
    }
  }
  const std::int64_t ignored = static_cast<std::int64_t>(truth.total()) - tp - fp - fn - tn;
  return {{"tp", tp}, {"fp", fp},           {"fn", fn},
          {"tn", tn}, {"unknown", unknown}, {"ignored", ignored}};
}

class Evaluation final : public Sink {
 public:
  enum Port { kDistance = 0, kTruth = 1, kMask = 2, kColor = 3 };

  explicit Evaluation(const StageContext& context)
      : path_(context.params.path("path")),
        image_dir_(context.params.boolean("save_images") ? image_dir_of(path_)
                                                         : std::filesystem::path()) {
    create_directory(path_.parent_path());
    if (!image_dir_.empty()) {
      for (const char* kind : {"mask", "truth", "color"}) create_directory(image_dir_ / kind);
    }
    file_ = std::fopen(path_.c_str(), "w");
    if (file_ == nullptr) {
      throw Error(path_.string() + ": cannot open for writing: " + std::strerror(errno) +
                  " (parameter 'path' must name a file in a writable directory)");
    }
  }
  ~Evaluation() override {
    if (file_ != nullptr) std::fclose(file_);
  }

  void consume(const Frame& frame) override {
    const FrameInfo& info = frame.info();
    json line = {{"frame_id", info.frame_id},
                 {"sequence", info.sequence},
                 {"device_timestamp_ns", info.device_timestamp_ns}};
    add_distance(frame, line);
    const GroundTruth* truth =
        frame.input(kTruth).empty() ? nullptr : &frame.input<GroundTruth>(kTruth);
    line["truth_mm"] = truth != nullptr && truth->distance_mm ? json(*truth->distance_mm) : json();
    const bool truth_mask = truth != nullptr && !truth->residue_mask.empty();
    line["truth_soil_fraction"] = truth_mask ? json(soil_fraction(truth->residue_mask)) : json();
    const ResidueMask* mask =
        frame.input(kMask).empty() ? nullptr : &frame.input<ResidueMask>(kMask);
    line["mask"] = mask != nullptr && truth_mask ? mask_counts(*mask, truth->residue_mask) : json();
    if (!image_dir_.empty()) {
      const std::string name = image_name(info.frame_id);
      if (mask != nullptr) write_image(image_dir_ / "mask" / (name + ".png"), mask->values);
      if (truth_mask) write_image(image_dir_ / "truth" / (name + ".png"), truth->residue_mask);
      if (!frame.input(kColor).empty()) {
        write_image(image_dir_ / "color" / (name + ".jpg"),
                    frame.input<RegisteredColor>(kColor).bgr);
      }
    }
    write(line.dump() + "\n");
  }

  void finish() override {
    if (std::fflush(file_) != 0) {
      throw Error(path_.string() + ": flush failed: " + std::strerror(errno));
    }
  }

 private:
  // frames.jsonl -> frames.images
  static std::filesystem::path image_dir_of(const std::filesystem::path& path) {
    return path.parent_path() / (path.stem().string() + ".images");
  }

  static void create_directory(const std::filesystem::path& dir) {
    if (dir.empty()) return;
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) throw Error(dir.string() + ": cannot create the directory: " + error.message());
  }

  static void add_distance(const Frame& frame, json& line) {
    if (frame.input(kDistance).empty()) {
      line["measured"] = false;
      line["distance_mm"] = nullptr;
      line["valid"] = false;
      return;
    }
    const auto& distance = frame.input<GroundDistance>(kDistance);
    line["measured"] = true;
    line["distance_mm"] = distance.valid ? json(distance.distance_mm) : json();
    line["valid"] = distance.valid;
    if (!distance.valid) line["cause"] = to_string(distance.cause);
    line["invalid_reason"] = distance.invalid_reason;
    line["soil_fraction"] = distance.soil_fraction;
    line["confidence"] = distance.confidence;
  }

  static double soil_fraction(const cv::Mat& truth_mask) {
    const cv::Mat soil = truth_mask == ResidueMask::kSoil;
    return static_cast<double>(cv::countNonZero(soil)) / static_cast<double>(truth_mask.total());
  }

  static std::string image_name(std::uint64_t frame_id) {
    char name[32];
    std::snprintf(name, sizeof name, "%06llu", static_cast<unsigned long long>(frame_id));
    return name;
  }

  static void write_image(const std::filesystem::path& file, const cv::Mat& image) {
    if (!cv::imwrite(file.string(), image)) throw Error(file.string() + ": cannot write the image");
  }

  void write(const std::string& text) {
    if (std::fputs(text.c_str(), file_) < 0) {
      throw Error(path_.string() + ": write failed: " + std::strerror(errno));
    }
  }

  const std::filesystem::path path_;
  const std::filesystem::path image_dir_;
  std::FILE* file_ = nullptr;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "sinks.evaluation";
  d.summary = "one JSON line per frame: distance, validity, ground truth, mask confusion counts";
  d.inputs = {
      PortSpec::of<GroundDistance>("distance", "the measurement; none = the chain gave none")
          .optional(),
      PortSpec::of<GroundTruth>("truth", "ground truth, when known").optional(),
      PortSpec::of<ResidueMask>("mask", "the predicted residue mask, compared with the truth's")
          .optional(),
      PortSpec::of<RegisteredColor>("color", "colour on the depth grid, saved with save_images")
          .optional(),
  };
  d.params = {
      ParamSpec::output_path("path", std::nullopt).describe("JSON-lines file to write (replaced)"),
      ParamSpec::boolean("save_images", false)
          .describe("also save each frame's mask, truth mask (PNG) and colour (JPEG) in the "
                    "folders mask/, truth/, color/ of PATH_STEM.images beside the file"),
  };
  d.create = factory<Evaluation>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::sinks
