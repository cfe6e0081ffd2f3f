// `tilth recording import-masks`: masks drawn in a labelling tool (CVAT, LabelMe) on a
// recording's colour images, or on its depth images, become the recording's residue
// masks (mask/NNNNNN.png and the mask column of frames.csv), each frame's carried onto
// the depth grid through the recording's own calibration (mask_registration.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace tilth::tools {

struct MaskImportOptions {
  std::filesystem::path recording;   // an image-folder recording
  std::filesystem::path labels;      // the export: label names, and the masks in it or below
  std::vector<std::string> residue;  // label names that are residue
  std::vector<std::string> soil;     // label names that are soil
  bool depth_grid = false;           // the masks were drawn on the depth images
  bool overwrite = false;            // replace frames' existing masks
};

struct MaskImportResult {
  std::filesystem::path masks;                       // the folder the masks were read from
  std::size_t imported = 0;                          // frames that got a mask
  std::vector<std::uint64_t> without_mask;           // indices of the frames that got none
  std::uint64_t residue = 0, soil = 0, unknown = 0;  // pixels of the masks written
};

// Checks everything it can before it writes: the recording, the label names and the
// classes, that every mask matches one frame (by the stem of its colour image's file
// name) and has the right size, and that no matched frame has a mask unless `overwrite`.
// Then writes each mask beside its final name, renames them all, and replaces
// frames.csv (a new file renamed over it); host_timestamps.csv and every other column
// stay as they were. Throws tilth::Error naming the file and what was expected; a
// failure leaves the recording as it was.
MaskImportResult import_masks(const MaskImportOptions& options);

}  // namespace tilth::tools
