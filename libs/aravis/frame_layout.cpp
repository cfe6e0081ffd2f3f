#include "frame_layout.h"

#include <string>

#include "tilth/error.h"

namespace tilth::aravis {
namespace {

std::string describe_parts(const BufferLayout& layout) {
  std::string text;
  const auto parts = layout.parts();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    text += (i == 0 ? "" : "; ") + std::string("part ") + std::to_string(i) + ": component " +
            std::to_string(parts[i].component_id) + ", " +
            describe_pixel_format(parts[i].pixel_format) + ", " + std::to_string(parts[i].width) +
            "x" + std::to_string(parts[i].height);
  }
  return text.empty() ? "no image parts" : text;
}

}  // namespace

void BufferLayout::add(const PartLayout& part) {
  if (part_count == kMaxParts) {
    throw Error("a buffer with more than " + std::to_string(kMaxParts) + " parts");
  }
  part_storage[part_count++] = part;
}

BufferLayout layout_of(ArvBuffer* buffer) {
  BufferLayout layout;
  layout.payload_type = arv_buffer_get_payload_type(buffer);
  if (layout.payload_type != ARV_BUFFER_PAYLOAD_TYPE_IMAGE &&
      layout.payload_type != ARV_BUFFER_PAYLOAD_TYPE_EXTENDED_CHUNK_DATA &&
      layout.payload_type != ARV_BUFFER_PAYLOAD_TYPE_MULTIPART) {
    return layout;
  }
  const guint count = arv_buffer_get_n_parts(buffer);
  for (guint i = 0; i < count; ++i) {
    PartLayout part;
    part.component_id = arv_buffer_get_part_component_id(buffer, i);
    part.data_type = arv_buffer_get_part_data_type(buffer, i);
    std::size_t size = 0;
    part.data = static_cast<const std::uint8_t*>(arv_buffer_get_part_data(buffer, i, &size));
    part.size = size;
    if (part.data_type == ARV_BUFFER_PART_DATA_TYPE_2D_IMAGE ||
        part.data_type == ARV_BUFFER_PART_DATA_TYPE_3D_IMAGE ||
        part.data_type == ARV_BUFFER_PART_DATA_TYPE_CONFIDENCE_MAP) {
      part.pixel_format = arv_buffer_get_part_pixel_format(buffer, i);
      gint x = 0;
      gint y = 0;
      gint width = 0;
      gint height = 0;
      arv_buffer_get_part_region(buffer, i, &x, &y, &width, &height);
      part.x_offset = x;
      part.y_offset = y;
      part.width = width;
      part.height = height;
      gint x_padding = 0;
      gint y_padding = 0;
      arv_buffer_get_part_padding(buffer, i, &x_padding, &y_padding);
      part.x_padding = x_padding;
    }
    layout.add(part);
  }
  return layout;
}

const PartLayout& tof_part(const BufferLayout& layout,
                           std::optional<std::uint32_t> range_component) {
  const auto parts = layout.parts();
  if (parts.size() == 1) return parts.front();
  if (range_component) {
    for (const auto& part : parts) {
      if (part.component_id == *range_component) return part;
    }
  }
  const PartLayout* found = nullptr;
  for (const auto& part : parts) {
    if (find_format(tof_formats(), part.pixel_format) == nullptr) continue;
    if (found != nullptr) {
      throw Error(
          "multi-part frame with several parts in a ToF format and no range component "
          "to choose by (" +
          describe_parts(layout) + ")");
    }
    found = &part;
  }
  if (found == nullptr) {
    throw Error("no part of the frame holds a raw ToF image" +
                (range_component ? " of range component " + std::to_string(*range_component)
                                 : std::string()) +
                " (" + describe_parts(layout) + ")");
  }
  return *found;
}

const PartLayout& component_part(const BufferLayout& layout, std::uint32_t component_id) {
  for (const auto& part : layout.parts()) {
    if (part.component_id == component_id) return part;
  }
  throw Error("no part of the frame belongs to component " + std::to_string(component_id) + " (" +
              describe_parts(layout) + ")");
}

const PartLayout& color_part(const BufferLayout& layout) {
  const auto parts = layout.parts();
  if (parts.size() == 1) return parts.front();
  const PartLayout* found = nullptr;
  for (const auto& part : parts) {
    if (part.data_type != ARV_BUFFER_PART_DATA_TYPE_2D_IMAGE) continue;
    if (found != nullptr) {
      throw Error("multi-part frame with several 2D image parts (" + describe_parts(layout) +
                  "); a colour camera stage takes one");
    }
    found = &part;
  }
  if (found == nullptr)
    throw Error("no part of the frame holds an image (" + describe_parts(layout) + ")");
  return *found;
}

cv::Mat wrap_part(const PartLayout& part, const ImageFormat& format) {
  if (part.pixel_format != format.arv) {
    throw Error("frame part is " + describe_pixel_format(part.pixel_format) + ", expected " +
                describe_pixel_format(format.arv));
  }
  if (part.width <= 0 || part.height <= 0 || part.x_padding < 0) {
    throw Error("frame part has no valid size (" + std::to_string(part.width) + "x" +
                std::to_string(part.height) + ", row padding " + std::to_string(part.x_padding) +
                ")");
  }
  const std::size_t row_bytes =
      static_cast<std::size_t>(part.width) * static_cast<std::size_t>(CV_ELEM_SIZE(format.cv_type));
  const std::size_t step = row_bytes + static_cast<std::size_t>(part.x_padding);
  const std::size_t needed = step * static_cast<std::size_t>(part.height - 1) + row_bytes;
  if (part.data == nullptr || part.size < needed) {
    throw Error("frame part of " + std::to_string(part.size) + " bytes is too small for " +
                std::to_string(part.width) + "x" + std::to_string(part.height) + " " +
                format.genicam_name + " (needs " + std::to_string(needed) + ")");
  }
  return cv::Mat(part.height, part.width, format.cv_type, const_cast<std::uint8_t*>(part.data),
                 step);
}

}  // namespace tilth::aravis
