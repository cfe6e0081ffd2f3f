// Files of the source tree that tests and benchmarks read: the shipped rigs (calib/),
// graphs and presets.
#pragma once

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace tilth::testing {

inline std::filesystem::path source_path(const std::filesystem::path& relative) {
  return std::filesystem::path(TILTH_SOURCE_DIR) / relative;
}

// calib/paper_rig.calib.json: the paper's rig, the default of every graph.
inline std::filesystem::path paper_rig_path() { return source_path("calib/paper_rig.calib.json"); }

inline nlohmann::json paper_rig_document() {
  std::ifstream in(paper_rig_path());
  return nlohmann::json::parse(in);
}

}  // namespace tilth::testing
