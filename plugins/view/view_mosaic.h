// What the live view shows of one frame: four panels side by side, rendered small enough
// for a tablet over Wi-Fi and encoded as one JPEG.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::view {

// One frame's messages, shared with the graph (no pixels copied); any may be null.
struct FrameMessages {
  std::uint64_t frame_id = 0;
  std::shared_ptr<const ColorImage> color;
  std::shared_ptr<const RegisteredColor> registered;
  std::shared_ptr<const ResidueMask> mask;
  std::shared_ptr<const DepthImage> depth;
  std::shared_ptr<const GroundDistance> distance;
};

// The panels, left to right and top to bottom: the colour camera; the residue mask (red)
// and the region of interest (yellow) on the registered colour; the depth as a colour
// map; the depth's edges (magenta) on the registered colour, where a misaligned rig shows
// as edges beside the colour's. `panel` is one panel's size; `roi` is in depth pixels.
// `mosaic` is drawn in place when it has the size already, as a renderer's reused image.
void render_mosaic(const FrameMessages& frame, cv::Size panel, std::optional<cv::Rect> roi,
                   cv::Mat& mosaic);

// JPEG bytes of `image` at `quality` (1-100).
std::vector<unsigned char> encode_jpeg(const cv::Mat& image, int quality);

}  // namespace tilth::view
