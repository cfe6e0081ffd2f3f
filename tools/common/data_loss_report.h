// The lines a tool prints when stages of its graph lost data (RunResult::data_lost).
#pragma once

#include <string>
#include <vector>

#include "framework/runtime.h"

namespace tilth::tools {

// One line per node, "PROGRAM: data lost: node 'csv' (sinks.csv): 37 frame(s) not
// stored; first report: ...", each ended by a newline; "" when nothing was lost.
std::string data_loss_report(const std::string& program, const std::vector<DataLoss>& losses);

}  // namespace tilth::tools
