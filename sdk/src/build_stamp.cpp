#include "tilth/build_stamp.h"

namespace tilth {
namespace {

const char* or_unknown(const char* field) { return field ? field : "?"; }

}  // namespace

std::string describe(const BuildStamp& stamp) {
  return std::string(or_unknown(stamp.compiler)) + ", " + or_unknown(stamp.standard_library) +
         ", OpenCV " + or_unknown(stamp.opencv) + ", nlohmann-json " + or_unknown(stamp.json);
}

}  // namespace tilth
