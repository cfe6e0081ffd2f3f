#include "framework/graph_session.h"

#include "tilth/log.h"

namespace tilth {

std::unique_ptr<StageRegistry> load_plugins(const std::filesystem::path& graph_dir,
                                            const std::vector<std::filesystem::path>& named) {
  auto registry = std::make_unique<StageRegistry>();
  for (const auto& file : named) registry->load(file);
  for (const auto& problem : registry->load_directories(plugin_search_path(graph_dir))) {
    log(LogLevel::kWarning, "plugins", problem);
  }
  return registry;
}

GraphSession open_graph(const std::filesystem::path& file, const GraphOverrides& overrides) {
  GraphSpec spec = load_graph(file, overrides);
  GraphSession session;
  const auto dir = file.parent_path().empty() ? std::filesystem::path(".") : file.parent_path();
  session.registry = load_plugins(dir, spec.plugins);
  session.graph = validate_graph(spec, *session.registry);
  return session;
}

}  // namespace tilth
