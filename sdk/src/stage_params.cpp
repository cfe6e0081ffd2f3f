#include "tilth/stage_params.h"

#include <string>
#include <utility>

#include "tilth/error.h"

namespace tilth {

Params stage_params(const StageDescriptor& descriptor, const nlohmann::json& overrides) {
  nlohmann::json values = nlohmann::json::object();
  for (const ParamSpec& spec : descriptor.params) values[spec.name] = spec.default_value;
  for (const auto& [name, value] : overrides.items()) {
    const ParamSpec* spec = descriptor.param(name);
    if (spec == nullptr) throw Error(descriptor.type + ": no parameter '" + name + "'");
    if (const std::string expected = spec->check(value); !expected.empty()) {
      throw Error(descriptor.type + ": parameter '" + name + "': expected " + expected + ", got " +
                  value.dump());
    }
    values[name] = value;
  }
  return Params(std::move(values));
}

}  // namespace tilth
