// The GenICam pixel formats the camera stages take, and what each becomes: a 16-bit
// raw ToF image, or a colour image with its tilth::PixelFormat. Every one of them is
// wrapped without copying.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <arv.h>

#include "tilth/messages/color_image.h"

namespace tilth::aravis {

struct ImageFormat {
  const char* genicam_name;  // as the PixelFormat feature spells it
  ArvPixelFormat arv;
  int cv_type;
  std::optional<PixelFormat> color;  // colour formats only
};

const std::vector<ImageFormat>& tof_formats();    // Mono16, Coord3D_C16
const std::vector<ImageFormat>& color_formats();  // Bayer 8-bit, RGB8, BGR8, Mono8

const ImageFormat* find_format(const std::vector<ImageFormat>& formats, ArvPixelFormat format);
std::vector<std::string> format_names(const std::vector<ImageFormat>& formats);
// "Mono16 (0x01100007)", or the hexadecimal code alone for a format Aravis cannot name.
std::string describe_pixel_format(ArvPixelFormat format);

}  // namespace tilth::aravis
