// The rig calibration a stage works with, frame by frame. Frames carry the calibration of
// the rig that captured them (a recording's own, or the one a camera source was given),
// as a RealSense frame carries its stream's intrinsics; a stage uses it. A file named by
// the stage's `calibration` parameter overrides it, with a warning that says what
// differs: a calibration is never swapped silently. What a stage derives from a
// calibration (lookup tables, maps) is made once per calibration.
//
//   const auto used = calibration_.for_frame(raw.rig);   // FrameCalibration<Tables>
//   project(raw, used->derived);
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/log.h"
#include "tilth/param_spec.h"
#include "tilth/params.h"

namespace tilth {

// The `calibration` parameter of a stage that reads frames' calibrations: "" (the
// default) uses the frames' own.
ParamSpec frame_calibration_param();

// "" when `a` and `b` describe the same rig; otherwise their differences, e.g.
// "/depth_to_color/T_mm/0: 45 here, 40 there".
std::string calibration_differences(const RigCalibration& a, const RigCalibration& b);

template <class Derived>
class FrameCalibration {
 public:
  // A calibration and what the stage derived from it.
  struct Used {
    std::shared_ptr<const RigCalibration> rig;
    Derived derived;
  };
  using Derive = std::function<Derived(const RigCalibration&)>;

  // Loads and derives the parameter's file now, if one is named, so that its errors come
  // at start-up.
  FrameCalibration(const Params& params, Logger log, Derive derive)
      : log_(std::move(log)), derive_(std::move(derive)) {
    if (const std::filesystem::path file = params.path("calibration"); !file.empty()) {
      override_ = make(std::make_shared<const RigCalibration>(load_calibration(file)));
    }
  }

  // Thread-safe. `carried` is the frame's calibration, null when it carries none.
  std::shared_ptr<const Used> for_frame(const std::shared_ptr<const RigCalibration>& carried) {
    std::lock_guard lock(mutex_);
    if (override_ != nullptr) {
      if (carried != nullptr && carried != last_carried_) warn_if_overridden(*carried);
      last_carried_ = carried;
      return override_;
    }
    if (carried == nullptr) {
      throw Error(
          "the frame carries no rig calibration and parameter 'calibration' names none: name "
          "the rig's calibration file, or use a source whose frames carry one (a recording, "
          "the simulator, or a camera source given its 'calibration')");
    }
    if (current_ == nullptr || current_->rig != carried) current_ = make(carried);
    return current_;
  }

 private:
  std::shared_ptr<const Used> make(std::shared_ptr<const RigCalibration> rig) const {
    Derived derived = derive_(*rig);
    return std::make_shared<const Used>(Used{std::move(rig), std::move(derived)});
  }

  void warn_if_overridden(const RigCalibration& carried) const {
    const std::string differences = calibration_differences(*override_->rig, carried);
    if (differences.empty()) return;
    log_.warning("parameter 'calibration' (" + override_->rig->origin +
                 ") overrides the calibration the frames carry (" + carried.origin +
                 "), which differs: " + differences);
  }

  const Logger log_;
  const Derive derive_;
  std::shared_ptr<const Used> override_;
  std::mutex mutex_;
  std::shared_ptr<const Used> current_;
  std::shared_ptr<const RigCalibration> last_carried_;
};

}  // namespace tilth
