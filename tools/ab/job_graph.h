// The graph of one job of a comparison: one recording replayed through one variant's
// chain into a sinks.evaluation sink. The replay part is written as a graph file that
// includes the chain (so it can be read, and run with `tilth run`); the variant's
// changes are applied to the loaded graph, with their own locations for messages.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "framework/diagnostics.h"
#include "framework/graph_loader.h"
#include "framework/graph_validator.h"
#include "framework/stage_registry.h"
#include "recording_list.h"
#include "variant.h"

namespace tilth::ab {

struct JobFiles {
  std::filesystem::path graph;   // the replay graph file
  std::filesystem::path frames;  // the evaluation sink's JSON lines
  std::filesystem::path images;  // where it saves images: frames.images beside frames
  std::filesystem::path record;  // the job's outcome and stage times (job_record.h)
};

struct JobOptions {
  GraphOverrides variables;  // --var, for every graph file
  std::size_t max_in_flight = 4;
  bool save_images = false;  // masks and truth masks of every frame
  bool save_color = false;   // also the registered colour
};

// "variant@recording": the prefix of the chain's nodes in the job's graph, so log lines
// and errors name the job.
std::string job_label(const Variant& variant, const Recording& recording);

// Loads the variant's chain and checks the settings' node names and the ports against
// it; drops the default optional ports the chain has no node for. Returns the plugin
// libraries the chain names.
std::vector<std::filesystem::path> check_variant(Variant& variant, const GraphOverrides& variables,
                                                 Diagnostics& problems);

// Checks that every stage type a variant names is known, with the variant's location.
void check_stage_types(const Variant& variant, const StageRegistry& registry,
                       Diagnostics& problems);

// Writes the replay graph file and returns the job's validated graph, or adds its
// problems and returns nothing.
std::optional<ValidatedGraph> job_graph(const Variant& variant, const Recording& recording,
                                        const JobFiles& files, const JobOptions& options,
                                        const StageRegistry& registry, Diagnostics& problems);

}  // namespace tilth::ab
