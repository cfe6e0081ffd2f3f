// What a stage is constructed with: its node name, checked parameters, a logger, and
// access to the running pipeline's metrics.
#pragma once

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
};

}  // namespace tilth
