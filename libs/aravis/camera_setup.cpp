#include "camera_setup.h"

#include <sstream>

#include "aravis/gobject_ptr.h"
#include "camera_features.h"

namespace tilth::aravis {
namespace {

std::string number_text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

class Setup {
 public:
  Setup(ArvCamera* camera, const std::string& label, const Logger& log)
      : camera_(camera),
        features_(arv_camera_get_device(camera), label),
        label_(label),
        log_(log) {}

  // `component` enabled alone, then `companion` (if any) beside it, each delivered as a
  // part of multi-part payloads; `component` is left selected for the settings after it
  // (pixel format, Scan3d features), which apply to the selected component.
  void select_components(const std::string& component, const std::string& companion,
                         CameraDescription& description) {
    if (!features_.available("ComponentSelector")) {
      if (!companion.empty()) {
        throw Error("camera " + label_ +
                    " has no components (ComponentSelector), so it cannot "
                    "stream component '" +
                    companion + "' beside its image");
      }
      log_.info("camera " + label_ + " has no components (ComponentSelector): streaming its image");
      return;
    }
    description.component_id = select(component, ARV_COMPONENT_SELECTION_FLAGS_EXCLUSIVE_ENABLE);
    if (companion.empty()) {
      log_.info("component " + component + " selected and enabled alone (component id " +
                std::to_string(*description.component_id) + ")");
      return;
    }
    description.companion_id = select(companion, ARV_COMPONENT_SELECTION_FLAGS_ENABLE);
    select(component, ARV_COMPONENT_SELECTION_FLAGS_NONE);
    log_.info("components " + component + " (component id " +
              std::to_string(*description.component_id) + ") and " + companion + " (component id " +
              std::to_string(*description.companion_id) + ") enabled, " + component + " selected");
  }

  void set_feature(const std::string& name, const nlohmann::json& value) {
    const std::string read_back = features_.set(name, value);
    const std::string asked = value.is_string() ? value.get<std::string>() : value.dump();
    if (read_back == asked) {
      log_.info(name + " = " + read_back);
    } else {
      log_.warning(name + " set to " + asked + ", camera reads back " + read_back);
    }
  }

  void check_format(const std::vector<ImageFormat>& formats, CameraDescription& description) {
    description.pixel_format = features_.read("PixelFormat");
    GErrorSlot error;
    const ArvPixelFormat current = arv_camera_get_pixel_format(camera_, error.out());
    error.check("reading the pixel format of camera " + label_);
    if (find_format(formats, current) != nullptr) return;
    std::string names;
    for (const auto& name : format_names(formats)) names += (names.empty() ? "" : ", ") + name;
    throw Error("camera " + label_ + " streams pixel format " + description.pixel_format +
                ", which this stage cannot take; set pixel_format to one of " + names);
  }

  void set_trigger(const std::string& mode, const std::string& source) {
    if (mode.empty() && source.empty()) return;
    if (features_.available("TriggerSelector")) set_feature("TriggerSelector", "FrameStart");
    if (!mode.empty()) set_feature("TriggerMode", mode);
    if (!source.empty()) set_feature("TriggerSource", source);
  }

  // A value set through one of Aravis's camera calls, which know each vendor's feature
  // names (ExposureTime or ExposureTimeAbs, Gain or GainRaw, ...).
  template <class IsAvailable, class Set, class Get>
  void set_standard(const std::string& what, const std::string& features, double value,
                    IsAvailable is_available, Set set, Get get) {
    GErrorSlot error;
    if (!is_available(camera_, error.out())) {
      throw Error("camera " + label_ + " has no " + what + " feature (" + features + ")");
    }
    set(camera_, value, error.out());
    error.check("setting the " + what + " of camera " + label_ + " to " + number_text(value));
    const double read_back = get(camera_, error.out());
    error.check("reading the " + what + " of camera " + label_);
    log_.info(what + " = " + number_text(read_back) +
              (read_back == value ? "" : " (asked " + number_text(value) + ")"));
  }

  void set_packet_size(std::int64_t bytes) {
    require("GevSCPSPacketSize", "packet_size");
    GErrorSlot error;
    arv_camera_gv_set_packet_size(camera_, static_cast<gint>(bytes), error.out());
    error.check("setting the packet size of camera " + label_);
    const guint read_back = arv_camera_gv_get_packet_size(camera_, error.out());
    error.check("reading the packet size of camera " + label_);
    log_.info("packet size = " + std::to_string(read_back) + " bytes");
  }

  void set_packet_delay(std::int64_t delay_ns) {
    require("GevSCPD", "packet_delay_ns");
    GErrorSlot error;
    arv_camera_gv_set_packet_delay(camera_, delay_ns, error.out());
    error.check("setting the packet delay of camera " + label_);
    const gint64 read_back = arv_camera_gv_get_packet_delay(camera_, error.out());
    error.check("reading the packet delay of camera " + label_);
    log_.info("packet delay = " + std::to_string(read_back) + " ns");
  }

  // The camera's own conversion of its 16-bit range values to millimetres.
  void read_scan3d(CameraDescription& description) {
    if (!features_.available("Scan3dCoordinateScale")) return;
    if (features_.available("Scan3dCoordinateSelector")) {
      set_feature("Scan3dCoordinateSelector", "CoordinateC");
    }
    if (features_.available("Scan3dDistanceUnit")) {
      const std::string unit = features_.read("Scan3dDistanceUnit");
      if (unit != "Millimeter") {
        throw Error("camera " + label_ + " gives distances in " + unit +
                    " (Scan3dDistanceUnit); only Millimeter is supported");
      }
    }
    description.scale_mm = features_.read_number("Scan3dCoordinateScale");
    description.offset_mm = features_.available("Scan3dCoordinateOffset")
                                ? features_.read_number("Scan3dCoordinateOffset")
                                : 0.0;
    log_.info("range scale " + number_text(*description.scale_mm) + " mm per value, offset " +
              number_text(*description.offset_mm) + " mm (Scan3dCoordinateScale / Offset)");
  }

  void require_software_trigger() {
    GErrorSlot error;
    const bool supported = arv_camera_is_software_trigger_supported(camera_, error.out());
    error.check("reading whether camera " + label_ + " takes a software trigger");
    if (!supported) {
      throw Error("camera " + label_ +
                  " has no software trigger (TriggerSoftware), which trigger_mode host_clock "
                  "fires");
    }
  }

  void describe(double software_trigger_hz, CameraDescription& description) {
    GErrorSlot error;
    if (software_trigger_hz > 0.0) {
      description.frame_rate_hz = software_trigger_hz;
    } else if (arv_camera_is_frame_rate_available(camera_, nullptr)) {
      description.frame_rate_hz = arv_camera_get_frame_rate(camera_, error.out());
      error.check("reading the frame rate of camera " + label_);
    }
    description.payload_bytes = arv_camera_get_payload(camera_, error.out());
    error.check("reading the payload size of camera " + label_);
  }

 private:
  std::uint32_t select(const std::string& component, ArvComponentSelectionFlags flags) {
    guint id = 0;
    GErrorSlot error;
    arv_camera_select_component(camera_, component.c_str(), flags, &id, error.out());
    error.check("selecting component '" + component + "' of camera " + label_ +
                " (ComponentSelector / ComponentEnable)");
    return id;
  }

  void require(const std::string& feature, const std::string& param) {
    if (!features_.available(feature)) {
      throw Error("camera " + label_ + " has no feature '" + feature + "' (parameter " + param +
                  ")");
    }
  }

  ArvCamera* camera_;
  CameraFeatures features_;
  const std::string& label_;
  const Logger& log_;
};

}  // namespace

CameraDescription configure_camera(ArvCamera* camera, const std::string& label,
                                   const CameraSettings& settings, const Logger& log) {
  arv_camera_set_range_check_policy(camera, ARV_RANGE_CHECK_POLICY_ENABLE);
  arv_camera_set_access_check_policy(camera, ARV_ACCESS_CHECK_POLICY_ENABLE);
  // A camera left streaming (by a process that died) refuses most settings.
  arv_camera_stop_acquisition(camera, nullptr);

  CameraDescription description;
  description.label = label;
  Setup setup(camera, label, log);
  if (!settings.component.empty()) {
    setup.select_components(settings.component, settings.companion_component, description);
  }
  if (!settings.pixel_format.empty()) setup.set_feature("PixelFormat", settings.pixel_format);
  setup.set_trigger(settings.trigger_mode, settings.trigger_source);
  if (settings.software_trigger_hz > 0.0) setup.require_software_trigger();
  if (settings.exposure_us > 0.0) {
    setup.set_standard("exposure time", "ExposureTime or ExposureTimeAbs", settings.exposure_us,
                       arv_camera_is_exposure_time_available, arv_camera_set_exposure_time,
                       arv_camera_get_exposure_time);
  }
  if (settings.gain >= 0.0) {
    setup.set_standard("gain", "Gain or GainRaw", settings.gain, arv_camera_is_gain_available,
                       arv_camera_set_gain, arv_camera_get_gain);
  }
  if (settings.frame_rate_hz > 0.0) {
    setup.set_standard("frame rate", "AcquisitionFrameRate", settings.frame_rate_hz,
                       arv_camera_is_frame_rate_available, arv_camera_set_frame_rate,
                       arv_camera_get_frame_rate);
  }
  if (settings.packet_size > 0) setup.set_packet_size(settings.packet_size);
  if (settings.packet_delay_ns >= 0) setup.set_packet_delay(settings.packet_delay_ns);
  for (const auto& feature : settings.features) setup.set_feature(feature.name, feature.value);
  setup.check_format(*settings.formats, description);
  setup.read_scan3d(description);
  setup.describe(settings.software_trigger_hz, description);
  return description;
}

}  // namespace tilth::aravis
