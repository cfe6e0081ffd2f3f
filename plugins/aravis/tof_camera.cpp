// aravis.tof_camera: raw ToF frames from a GigE Vision ToF camera (a Basler blaze-101).
// Mono16 or Coord3D_C16 pixels are passed on without copying, with the camera's own
// scale and offset to millimetres (Scan3dCoordinateScale / Scan3dCoordinateOffset) when
// it has them. The range component is selected on cameras with components, and taken
// from multi-part payloads by its component id. Given the rig's calibration, its frames
// carry it (tilth/frame_calibration.h).
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
  return settings;
}

class TofCamera final : public CameraSource {
 public:
  explicit TofCamera(const StageContext& context)
      : CameraSource(tof_settings(context.params), context), rig_(rig(context.params)) {}

 private:
  static std::shared_ptr<const RigCalibration> rig(const Params& params) {
    const std::filesystem::path file = params.path("calibration");
    if (file.empty()) return nullptr;
    return std::make_shared<const RigCalibration>(load_calibration(file));
  }

  std::shared_ptr<const Message> convert(const BufferLayout& layout, PoppedBuffer& buffer,
                                         const CameraDescription& camera,
                                         std::int64_t device_timestamp_ns) override {
    const PartLayout& part = tof_part(layout, camera.component_id);
    const ImageFormat* format = find_format(tof_formats(), part.pixel_format);
    if (format == nullptr) {
      throw Error("its image is " + describe_pixel_format(part.pixel_format) +
                  ", not Mono16 or Coord3D_C16");
    }
    auto raw = make_message<RawTofFrame>();
    raw->gray = wrap_part(part, *format);
    buffer.lend_to(raw->gray);
    raw->device_timestamp_ns = device_timestamp_ns;
    raw->scale_mm = camera.scale_mm;
    raw->offset_mm = camera.offset_mm;
    raw->rig = rig_;
    return raw;
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
  };
  d.params = camera_param_specs(tof_formats());
  d.params.push_back(
      ParamSpec::string("component", "Range")
          .describe("GenICam component to stream (ComponentSelector), enabled alone; its part "
                    "is taken from multi-part payloads; cameras without components ignore it"));
  d.params.push_back(ParamSpec::path("calibration", "")
                         .describe("the rig's calibration file, carried by every frame for the "
                                   "stages after it; \"\" = none"));
  d.create = factory<TofCamera>();
  return d;
}

}  // namespace tilth::aravis

TILTH_STAGE(tilth::aravis::describe_tof_camera());
