// aravis.tof_camera: raw ToF frames from a GigE Vision ToF camera (a Basler blaze-101).
// Mono16 or Coord3D_C16 pixels are passed on without copying, with the camera's own
// scale and offset to millimetres (Scan3dCoordinateScale / Scan3dCoordinateOffset) when
// it has them. The range component is selected on cameras with components, and taken
// from multi-part payloads by its component id; an intensity component can stream beside
// it, in the same payloads, for the stages that need to see the scene (calibration).
// Given the rig's calibration, its frames carry it (tilth/frame_calibration.h).
#include "camera_source.h"
#include "camera_stages.h"
#include "tilth/calibration.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"

namespace tilth::aravis {
namespace {

CameraSettings tof_settings(const Params& params) {
  CameraSettings settings = read_camera_settings(params, tof_formats());
  settings.component = params.string("component");
  settings.companion_component = params.string("intensity_component");
  if (!settings.companion_component.empty() && settings.component.empty()) {
    throw Error("intensity_component '" + settings.companion_component +
                "' streams beside the range component, and component is empty");
  }
  return settings;
}

class TofCamera final : public CameraSource {
 public:
  enum Port { kIntensity = kStatus + 1 };

  explicit TofCamera(const StageContext& context)
      : CameraSource(tof_settings(context.params), context), rig_(rig(context.params)) {}

 private:
  static std::shared_ptr<const RigCalibration> rig(const Params& params) {
    const std::filesystem::path file = params.path("calibration");
    if (file.empty()) return nullptr;
    return std::make_shared<const RigCalibration>(load_calibration(file));
  }

  void convert(const BufferLayout& layout, PoppedBuffer& buffer, const CameraDescription& camera,
               std::int64_t device_timestamp_ns, Frame& frame) override {
    const PartLayout& part = tof_part(layout, camera.component_id);
    const ImageFormat* format = find_format(tof_formats(), part.pixel_format);
    if (format == nullptr) {
      throw Error("its image is " + describe_pixel_format(part.pixel_format) +
                  ", not Mono16 or Coord3D_C16");
    }
    auto raw = frame_of(wrap_part(part, *format), device_timestamp_ns);
    raw->scale_mm = camera.scale_mm;
    raw->offset_mm = camera.offset_mm;
    if (!camera.companion_id) {
      buffer.lend_to(raw->gray);
      frame.set_output(kImage, std::move(raw));
      return;
    }
    const PartLayout& intensity_part = component_part(layout, *camera.companion_id);
    const ImageFormat* mono16 = find_format(tof_formats(), ARV_PIXEL_FORMAT_MONO_16);
    if (intensity_part.pixel_format != mono16->arv) {
      throw Error("its intensity is " + describe_pixel_format(intensity_part.pixel_format) +
                  ", not Mono16");
    }
    auto intensity = frame_of(wrap_part(intensity_part, *mono16), device_timestamp_ns);
    cv::Mat* const lent[] = {&raw->gray, &intensity->gray};
    buffer.lend_to(lent);
    frame.set_output(kImage, std::move(raw));
    frame.set_output(kIntensity, std::move(intensity));
  }

  std::shared_ptr<RawTofFrame> frame_of(cv::Mat gray, std::int64_t device_timestamp_ns) {
    auto message = make_message<RawTofFrame>();
    message->gray = std::move(gray);
    message->device_timestamp_ns = device_timestamp_ns;
    message->rig = rig_;
    return message;
  }

  const std::shared_ptr<const RigCalibration> rig_;
};

}  // namespace

StageDescriptor describe_tof_camera() {
  StageDescriptor d;
  d.type = "aravis.tof_camera";
  d.summary = "raw ToF frames (Mono16, Coord3D_C16) from a GigE Vision camera, through losses";
  d.outputs = {
      PortSpec::of<RawTofFrame>("raw",
                                "raw ToF values with the camera's scale and offset, no copy; "
                                "none while the camera is lost"),
      PortSpec::of<CameraStatus>("status", "streaming, problem and frame counts, every frame"),
      PortSpec::of<RawTofFrame>("intensity",
                                "the intensity (Mono16) of the same capture as raw, no copy; "
                                "only with intensity_component"),
  };
  d.params = camera_param_specs(tof_formats());
  d.params.push_back(
      ParamSpec::string("component", "Range")
          .describe("GenICam component to stream (ComponentSelector), enabled alone; its part "
                    "is taken from multi-part payloads; cameras without components ignore it"));
  d.params.push_back(
      ParamSpec::string("intensity_component", "")
          .describe("GenICam component streamed beside component, in the same multi-part "
                    "payloads, and passed on at intensity (Intensity on a blaze-101); \"\" = "
                    "none; needs a camera with components"));
  d.params.push_back(ParamSpec::path("calibration", "")
                         .describe("the rig's calibration file, carried by every frame for the "
                                   "stages after it; \"\" = none"));
  d.create = factory<TofCamera>();
  return d;
}

}  // namespace tilth::aravis

TILTH_STAGE(tilth::aravis::describe_tof_camera());
