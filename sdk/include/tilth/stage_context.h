// What a stage is constructed with: its node name, checked parameters, a logger, access
// to the running pipeline's metrics, where to report data it could not store, and how to
// end the run when it cannot go on.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "tilth/log.h"
#include "tilth/messages/pipeline_metrics.h"
#include "tilth/params.h"

namespace tilth {

struct StageContext {
  std::string node;
  Params params;
  Logger log{""};
  std::function<PipelineMetrics()> pipeline_metrics;
  // A stage that could not store what it was given (a full disk) reports it here and
  // goes on: the frames this report loses, and why (the file, the error, what is lost so
  // far). The runtime logs a node's first report, counts the frames, and the run ends
  // with data lost (docs/runtime.md, "Lost data"). Thread-safe.
  std::function<void(std::uint64_t frames, const std::string& why)> report_data_loss =
      [](std::uint64_t, const std::string&) {};
  // A stage that cannot go on at all (the reader of its output has gone: a closed pipe)
  // ends the run as a stop signal would: sources stop, frames in flight finish, every sink
  // flushes. The runtime logs the node and `why`. Thread-safe.
  std::function<void(const std::string& why)> end_run = [](const std::string&) {};
};

}  // namespace tilth
