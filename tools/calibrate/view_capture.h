// `tilth calibrate capture`: views for `tilth calibrate solve` kept from a stream of frame
// pairs (camera_pairs.h), each as NNN_intensity.png and NNN_color.png in a folder, with
// the images' coverage told as it grows, so the user knows where to hold the board next.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>

#include "board_coverage.h"
#include "camera_pairs.h"
#include "view_selector.h"

namespace tilth::calibrate {

struct CaptureOptions {
  std::filesystem::path out;  // created with the first view; must hold no views yet
  std::size_t views = 20;     // stop after keeping this many
  SelectorOptions selection;  // its colour image size is the first pair's
};

struct CaptureResult {
  std::uint64_t pairs = 0;        // frame pairs looked at
  std::uint64_t board_pairs = 0;  // with the board found in both images
  std::size_t kept = 0;
  bool stopped = false;                         // a stop signal ended it
  std::optional<BoardCoverage> depth_coverage;  // none when no pair came
  std::optional<BoardCoverage> color_coverage;
};

// Looks at `stream`'s pairs until `views` are kept, the stream ends or a stop signal, and
// writes each kept view (the intensity as received, the colour as BGR or
// grey) as soon as it is kept, to temporary names renamed into place. Progress goes to
// `progress`: each kept view with the areas not reached yet, and each change of what
// holds a view back (no board, moving, seen before). Throws tilth::Error when the folder
// holds views already or a file cannot be written, naming it.
CaptureResult capture_views(const PairStream& stream, CaptureOptions options,
                            std::ostream& progress);

}  // namespace tilth::calibrate
