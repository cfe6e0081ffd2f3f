#include "merge.h"

#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "command_line.h"
#include "exit_codes.h"
#include "job_graph.h"
#include "job_record.h"
#include "options.h"
#include "report_files.h"
#include "shard_manifest.h"
#include "tilth/error.h"

namespace tilth::ab {
namespace {

namespace fs = std::filesystem;

const char* const kMergeUsage =
    R"(usage: tilth ab merge SHARD_DIR... --out DIR [--overwrite] [--quiet]

Writes the report of a comparison run as shards ('tilth ab ... --shard I/N --out
SHARD_DIR', on one machine or many) from the results they left in the SHARD_DIRs: the
same report.html, summary.json, summary.csv, conditions.csv and frames.csv that one run
would have written, apart from timings and the stamp of how it was made. Every shard
must have run the same comparison (variants, baseline, recordings, tags, variables). A
job whose shard did not finish is in the report as failed ("missing") and listed here,
with exit code 1: run that shard again, then merge again.

  --out DIR      where the report goes; missing or empty
  --overwrite    replace an earlier report in DIR
  --quiet        no summary
)";

class MergeUsageError : public Error {
 public:
  using Error::Error;
};

// A finished shard and the folder holding its results.
struct ShardResults {
  ShardManifest manifest;
  OutputLayout layout;
};

std::vector<ShardResults> finished_shards(const std::vector<std::string>& folders) {
  std::vector<ShardResults> shards;
  for (const auto& folder : folders) {
    const OutputLayout layout{fs::absolute(folder).lexically_normal()};
    if (!fs::is_directory(layout.dir)) throw MergeUsageError(folder + ": no such folder");
    const auto manifests = read_shard_manifests(layout);
    if (manifests.empty()) {
      std::cerr << "tilth ab merge: " << folder
                << ": no shard finished here (no shards/I-of-N.json)\n";
    }
    for (const auto& manifest : manifests) shards.push_back({manifest, layout});
  }
  if (shards.empty()) throw Error("no finished shard in the folders given; nothing to merge");
  const ShardManifest& first = shards.front().manifest;
  for (const auto& [manifest, layout] : shards) {
    if (manifest.shard.count != first.shard.count) {
      throw Error(manifest.file.string() + " is shard " + manifest.shard.text() + " and " +
                  first.file.string() + " shard " + first.shard.text() +
                  ": not shards of one comparison");
    }
    if (manifest.comparison != first.comparison) {
      throw Error(manifest.file.string() + " and " + first.file.string() +
                  " ran different comparisons (their variants, baseline, recordings, tags, "
                  "variables, --no-soil-below or --overlays differ)");
    }
  }
  return shards;
}

// The comparison's options from a shard's command line, read where it was given, as the
// shard read them.
Options options_of(const ShardManifest& manifest) {
  std::vector<std::string> arguments = manifest.arguments;
  std::vector<char*> argv{const_cast<char*>("tilth-ab")};
  for (auto& argument : arguments) argv.push_back(argument.data());
  const fs::path here = fs::current_path();
  Options options;
  try {
    fs::current_path(manifest.working_directory);
    options = parse_options(static_cast<int>(argv.size()), argv.data());
    Diagnostics problems;
    for (auto& variant : options.variants) check_variant(variant, options.variables, problems);
    if (!problems.empty()) throw Error(problems.items().front().text());
  } catch (const std::exception& error) {
    fs::current_path(here);
    throw Error(manifest.file.string() + ": the shard's command line, read again in " +
                manifest.working_directory.string() + ": " + error.what());
  }
  fs::current_path(here);
  if (comparison_identity(options) != manifest.comparison) {
    throw Error(manifest.file.string() +
                ": its command line no longer gives the comparison the shard ran (were "
                "recordings or variant files changed since?)");
  }
  return options;
}

// The shard that ran each job, by the job's index.
std::map<std::size_t, const ShardResults*> job_owners(const std::vector<ShardResults>& shards,
                                                      std::size_t jobs) {
  std::map<std::size_t, const ShardResults*> owners;
  for (const auto& shard : shards) {
    for (const std::size_t job : shard.manifest.jobs) {
      if (job >= jobs || !shard.manifest.shard.contains(job)) {
        throw Error(shard.manifest.file.string() + ": job " + std::to_string(job) +
                    " is not one of shard " + shard.manifest.shard.text() + "'s");
      }
      const auto [at, added] = owners.emplace(job, &shard);
      if (!added) {
        throw Error("job " + std::to_string(job) + " has results in both " +
                    at->second->layout.dir.string() + " and " + shard.layout.dir.string() +
                    ": give the folder of one of them");
      }
    }
  }
  return owners;
}

// The merge's own command line, and each shard's.
ReportStamp merge_stamp(const std::vector<std::string>& arguments,
                        const std::vector<ShardResults>& shards) {
  ReportStamp stamp{command_line_of(arguments), fs::current_path(), {}};
  for (const auto& shard : shards) {
    stamp.shard_command_lines.push_back(command_line_of(shard.manifest.arguments));
  }
  return stamp;
}

int merge(const cli::CommandLine& line, const std::vector<std::string>& arguments) {
  if (line.positional().empty()) throw MergeUsageError("no shard folder given");
  const auto out = line.value("--out");
  if (!out) throw MergeUsageError("--out DIR is required");
  const std::vector<ShardResults> shards = finished_shards(line.positional());
  Options options = options_of(shards.front().manifest);
  const Shard any = shards.front().manifest.shard;
  const std::size_t recordings = options.recordings.size();
  const auto owners = job_owners(shards, options.variants.size() * recordings);

  Comparison comparison{options.variants,      options.recordings, {},
                        options.no_soil_below, options.baseline,   merge_stamp(arguments, shards)};
  std::vector<std::string> missing;
  for (std::size_t v = 0; v < options.variants.size(); ++v) {
    for (std::size_t r = 0; r < recordings; ++r) {
      const std::size_t job = v * recordings + r;
      const Shard shard{job % any.count, any.count};
      const Variant& variant = options.variants[v];
      const Recording& recording = options.recordings[r];
      if (const auto owner = owners.find(job); owner != owners.end()) {
        comparison.jobs.push_back(read_job_record(
            owner->second->layout.job(variant.name, recording.name), options.no_soil_below));
        continue;
      }
      JobResult result;
      result.failed = true;
      result.failure = "missing: shard " + shard.text() + " left no result of this job";
      comparison.jobs.push_back(result);
      missing.push_back("shard " + shard.text() + ": " + job_label(variant, recording));
    }
  }

  options.layout.dir = fs::absolute(*out).lexically_normal();
  try {
    prepare_output(options.layout, line.flag("--overwrite"));
  } catch (const Error& error) {
    throw MergeUsageError(std::string("--out ") + error.what());
  }
  const ReportFigures figures = report_figures(comparison);
  write_report(comparison, figures, options.layout, options.overlays);
  if (!line.flag("--quiet")) print_summary(comparison, figures, options.layout);
  if (!missing.empty()) {
    std::cerr << "tilth ab merge: " << missing.size() << " of " << comparison.jobs.size()
              << " jobs missing (their shard did not finish: run it again, then merge again):\n";
    for (const auto& job : missing) std::cerr << "  " << job << "\n";
  }
  for (const auto& job : comparison.jobs) {
    if (job.failed && !job.failure.starts_with("missing: ")) {
      std::cerr << "tilth ab merge: a graph failed: " << job.failure << "\n";
    }
  }
  return comparison.any_failed() ? kExitFailed : kExitOk;
}

}  // namespace

int merge_command(int argc, char** argv) {
  try {
    std::optional<cli::CommandLine> line;
    try {
      line.emplace(argc, argv, 2, std::set<std::string>{"--out"},
                   std::set<std::string>{"--help", "--overwrite", "--quiet"});
    } catch (const Error& error) {
      throw MergeUsageError(error.what());
    }
    if (line->flag("--help")) {
      std::cout << kMergeUsage;
      return kExitOk;
    }
    return merge(*line, std::vector<std::string>(argv + 1, argv + argc));
  } catch (const MergeUsageError& error) {
    std::cerr << "tilth ab merge: " << error.what() << "\n\n" << kMergeUsage;
    return kExitUsage;
  } catch (const Error& error) {
    std::cerr << "tilth ab merge: " << error.what() << "\n";
    return kExitFailed;
  }
}

}  // namespace tilth::ab
