#include "framework/diagnostics.h"

#include "tilth/json_input.h"

namespace tilth {

std::string Location::text() const {
  if (line > 0) return file + ":" + std::to_string(line) + ":" + std::to_string(column);
  if (pointer.empty()) return file;
  return file + ":" + pointer;
}

Location Location::child(const std::string& key) const {
  Location nested = *this;
  nested.pointer += "/" + json_pointer_token(key);
  return nested;
}

void Diagnostics::add(Location where, std::string message) {
  items_.push_back({std::move(where), std::move(message)});
}

std::string Diagnostics::text() const {
  std::string all;
  for (const auto& item : items_) {
    if (!all.empty()) all += "\n";
    all += item.text();
  }
  return all;
}

void Diagnostics::throw_if_any() const {
  if (!empty()) throw GraphError(*this);
}

}  // namespace tilth
