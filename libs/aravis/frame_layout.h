// Where the pixels of each part of a received buffer are, as Aravis describes them (one
// part for an image payload, several for a GigE Vision 2 multi-part payload), which part
// a stage takes, and that part's pixels as a cv::Mat header over the buffer.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include <arv.h>
#include <opencv2/core/mat.hpp>

#include "pixel_formats.h"

namespace tilth::aravis {

struct PartLayout {
  std::uint32_t component_id = 0;  // the GenICam component the part belongs to
  ArvBufferPartDataType data_type = ARV_BUFFER_PART_DATA_TYPE_UNKNOWN;
  ArvPixelFormat pixel_format = 0;
  int width = 0;
  int height = 0;
  int x_offset = 0;  // the image's top-left pixel on the sensor (a region of interest)
  int y_offset = 0;
  int x_padding = 0;  // bytes after each row
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;  // bytes
};

struct BufferLayout {
  static constexpr std::size_t kMaxParts = 8;
  ArvBufferPayloadType payload_type = ARV_BUFFER_PAYLOAD_TYPE_UNKNOWN;
  std::array<PartLayout, kMaxParts> part_storage{};
  std::size_t part_count = 0;

  std::span<const PartLayout> parts() const { return {part_storage.data(), part_count}; }
  void add(const PartLayout& part);  // throws beyond kMaxParts
};

// The parts of a complete buffer: none for payloads without an image (chunk data, JPEG).
BufferLayout layout_of(ArvBuffer* buffer);

// The part holding a raw ToF image: the only part; in a multi-part payload the part of
// `range_component` when the camera named one, else the only part in a ToF format.
// Throws tilth::Error describing the parts when none fits.
const PartLayout& tof_part(const BufferLayout& layout,
                           std::optional<std::uint32_t> range_component);
// The part of component `component_id` (as the camera numbers its components). Throws
// tilth::Error describing the parts when the frame has none.
const PartLayout& component_part(const BufferLayout& layout, std::uint32_t component_id);
// The part holding a colour image: the only part, or the only 2D image part.
const PartLayout& color_part(const BufferLayout& layout);

// The part's pixels as a cv::Mat header of `format` (no copy, not owning), after
// checking that the part is in that format and its rows lie inside it.
cv::Mat wrap_part(const PartLayout& part, const ImageFormat& format);

}  // namespace tilth::aravis
