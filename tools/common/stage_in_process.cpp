#include "stage_in_process.h"

namespace tilth::tools {

StageInstance make_stage(const StageRegistry& registry, const std::string& type,
                         const nlohmann::json& given) {
  const StageRegistry::Entry* entry = registry.find(type);
  if (entry == nullptr) {
    throw Error("stage type '" + type + "' is not provided by any loaded plugin");
  }
  nlohmann::json values = nlohmann::json::object();
  for (const ParamSpec& spec : entry->descriptor.params) values[spec.name] = spec.default_value;
  for (const auto& [name, value] : given.items()) {
    const ParamSpec* spec = entry->descriptor.param(name);
    if (spec == nullptr) throw Error(type + ": no parameter '" + name + "'");
    if (const std::string expected = spec->check(value); !expected.empty()) {
      throw Error(type + ": parameter '" + name + "': expected " + expected + ", got " +
                  value.dump());
    }
    values[name] = value;
  }
  StageContext context;
  context.node = type;
  context.params = Params(std::move(values));
  context.log = Logger(type);
  return registry.create(type, context);
}

}  // namespace tilth::tools
