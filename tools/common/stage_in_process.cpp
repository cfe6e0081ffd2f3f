#include "stage_in_process.h"

#include "tilth/stage_params.h"

namespace tilth::tools {

StageInstance make_stage(const StageRegistry& registry, const std::string& type,
                         const nlohmann::json& given) {
  const StageRegistry::Entry* entry = registry.find(type);
  if (entry == nullptr) {
    throw Error("stage type '" + type + "' is not provided by any loaded plugin");
  }
  StageContext context;
  context.node = type;
  context.params = stage_params(entry->descriptor, given);
  context.log = Logger(type);
  return registry.create(type, context);
}

}  // namespace tilth::tools
