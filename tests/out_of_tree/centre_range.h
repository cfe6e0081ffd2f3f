// Example plugin: the range (gray * mm per gray) at the pixel nearest the image centre,
// as a message type of the plugin's own.
#pragma once

#include <sstream>
#include <string>

#include "tilth/message.h"
#include "tilth/stage_descriptor.h"

namespace example {

struct CentreRange : tilth::MessageOf<CentreRange> {
  static constexpr std::string_view kTypeName = "example.CentreRange";
  double range_mm = 0.0;
  std::string summary() const override {
    std::ostringstream out;
    out.setf(std::ios::fixed);
    out.precision(2);
    out << "centre range " << range_mm << " mm";
    return out.str();
  }
};

tilth::StageDescriptor describe_centre_range();

}  // namespace example
