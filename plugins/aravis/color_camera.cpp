// aravis.color_camera: colour images from a GigE Vision camera (a Basler acA1300-75gc),
// Bayer 8-bit, RGB8, BGR8 or Mono8, passed on without copying with their pixel format.
#include "camera_source.h"
#include "camera_stages.h"
#include "tilth/messages/color_image.h"
#include "tilth/plugin.h"

namespace tilth::aravis {
namespace {

class ColorCamera final : public CameraSource {
 public:
  explicit ColorCamera(const StageContext& context)
      : CameraSource(read_camera_settings(context.params, color_formats()), context) {}

 private:
  void convert(const BufferLayout& layout, PoppedBuffer& buffer, const CameraDescription&,
               std::int64_t device_timestamp_ns, Frame& frame) override {
    const PartLayout& part = color_part(layout);
    const ImageFormat* format = find_format(color_formats(), part.pixel_format);
    if (format == nullptr) {
      throw Error("its image is " + describe_pixel_format(part.pixel_format) +
                  ", not a colour format this stage takes");
    }
    auto color = make_message<ColorImage>();
    color->pixels = wrap_part(part, *format);
    buffer.lend_to(color->pixels);
    color->format = *format->color;
    color->device_timestamp_ns = device_timestamp_ns;
    color->sensor_offset = cv::Point(part.x_offset, part.y_offset);
    frame.set_output(kImage, std::move(color));
  }
};

}  // namespace

StageDescriptor describe_color_camera() {
  StageDescriptor d;
  d.type = "aravis.color_camera";
  d.summary =
      "colour images (Bayer 8-bit, RGB8, BGR8, Mono8) from a GigE Vision camera, "
      "through losses";
  d.outputs = {
      PortSpec::of<ColorImage>("color",
                               "the image in the camera's pixel format, no copy, with its "
                               "place on the sensor; none while the camera is lost"),
      PortSpec::of<CameraStatus>("status", "streaming, problem and frame counts, every frame"),
  };
  d.params = camera_param_specs(color_formats());
  d.create = factory<ColorCamera>();
  return d;
}

}  // namespace tilth::aravis

TILTH_STAGE(tilth::aravis::describe_color_camera());
