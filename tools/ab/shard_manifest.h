// What a shard of a comparison (`tilth ab --shard I/N`) writes when its jobs are done:
// shards/I-of-N.json in its output folder, with the command line it ran and what its
// results depend on, so that `tilth ab merge` can rebuild the comparison, check that
// every shard ran the same one, and tell which jobs are missing.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "options.h"
#include "shard.h"

namespace tilth::ab {

struct ShardManifest {
  std::filesystem::path file;
  Shard shard;
  std::string version;                      // of the tilth that ran the shard
  std::filesystem::path working_directory;  // where its command line was given
  std::vector<std::string> arguments;       // of `tilth ab`, as given
  nlohmann::ordered_json comparison;        // comparison_identity() of its options
  std::vector<std::size_t> jobs;            // the indices of the jobs it ran, done
};

// Everything a comparison's numbers depend on: the variants, the recordings, the graph
// variables, the visible-soil threshold and the number of overlays.
nlohmann::ordered_json comparison_identity(const Options& options);

// Writes the manifest (atomically: a shard either finished or left no manifest).
void write_shard_manifest(const OutputLayout& layout, const ShardManifest& manifest);

// The manifests in `dir`/shards, by file name. Throws tilth::Error naming a malformed file.
std::vector<ShardManifest> read_shard_manifests(const OutputLayout& layout);

}  // namespace tilth::ab
