#include "variant.h"

#include <algorithm>

#include "tilth/error.h"

namespace tilth::ab {

void check_variant_name(const std::string& name, const std::string& where) {
  const bool allowed = !name.empty() && name.size() <= 64 &&
                       std::all_of(name.begin(), name.end(), [](unsigned char c) {
                         return std::isalnum(c) || c == '-' || c == '_';
                       });
  if (!allowed) {
    throw Error(where + ": variant name '" + name +
                "': expected 1-64 letters, digits, '-' or '_' (it names folders and columns)");
  }
}

}  // namespace tilth::ab
