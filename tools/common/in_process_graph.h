// A graph that a tool builds in code from stage types and runs in its own process, as
// `tilth run` runs a graph file: the plugins of the usual search path, the same
// validation and the same runtime. Tools name stages; the framework knows none.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "framework/graph_spec.h"
#include "framework/runtime.h"
#include "tilth/stage_descriptor.h"

namespace tilth::tools {

class InProcessGraph {
 public:
  // `program` ("tilth simulate") names the graph in messages; relative paths resolve
  // against the working directory.
  explicit InProcessGraph(std::string program);

  // A node with the parameters the program chose.
  void add_node(const std::string& name, const std::string& type,
                const nlohmann::json& params = nlohmann::json::object());
  // A parameter from a command-line option's text, typed by the parameter as `tilth run
  // --set` values are; a problem with it names the option.
  void set_from_option(const std::string& node, const std::string& param, const std::string& option,
                       const std::string& text);
  void add_edge(const std::string& from, const std::string& to);
  void set_runtime(RuntimeOptions options) { spec_.runtime = options; }
  // A stage type compiled into the program (a sink that hands the frames to the tool),
  // registered beside the plugins' when the graph runs.
  void add_stage_type(StageDescriptor descriptor);

  // Loads the plugins, validates (throws GraphError with every problem), makes the stages
  // (throws tilth::Error naming each that failed to start) and runs until the sources end,
  // `limits` are reached, or a stop signal stops it as it stops `tilth run` (RunResult::stopped;
  // the program calls install_stop_handlers first).
  RunResult run(RunLimits limits = {});
  // From any thread, a stage the program added among them: the run stops as on a stop
  // signal (frames in flight finish); before run(), it stops at once.
  void stop();

 private:
  NodeSpec& node(const std::string& name);

  const std::string program_;
  GraphSpec spec_;
  std::vector<StageDescriptor> own_types_;

  std::mutex mutex_;
  Runtime* running_ = nullptr;
  bool stop_wanted_ = false;
};

}  // namespace tilth::tools
