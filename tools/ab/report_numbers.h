// The numbers of a comparison as files: summary.json (everything the report shows),
// summary.csv (one row per variant and recording, and per variant over all
// recordings), conditions.csv (one row per variant and condition: residue cover, tags)
// and frames.csv (one row per variant, recording and frame). Stage times, frame rates
// and the report's date are the only things that change from run to run.
#pragma once

#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "comparison.h"
#include "overlays.h"
#include "report_figures.h"

namespace tilth::ab {

// Overlay frames per recording, in the recordings' order.
using Overlays = std::vector<std::vector<OverlayFrame>>;

nlohmann::ordered_json summary_json(const Comparison& comparison, const ReportFigures& figures,
                                    const Overlays& overlays);

// Parts of summary.json, also written by a shard (shard_manifest.h, job_record.h).
nlohmann::ordered_json stage_times_json(const std::vector<StageTime>& stages);
nlohmann::ordered_json variants_json(const std::vector<Variant>& variants);
nlohmann::ordered_json recordings_json(const std::vector<Recording>& recordings);

// Throw tilth::Error naming the file when it cannot be written.
void write_summary_csv(const Comparison& comparison, const ReportFigures& figures,
                       const std::filesystem::path& file);
void write_conditions_csv(const Comparison& comparison, const ReportFigures& figures,
                          const std::filesystem::path& file);
void write_frames_csv(const Comparison& comparison, const std::filesystem::path& file);
void write_text(const std::filesystem::path& file, const std::string& text);

}  // namespace tilth::ab
