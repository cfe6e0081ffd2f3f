// `tilth ab`: replays recordings through variants of the measurement chain, one graph
// per (variant, recording), several at once, and compares them with the ground truth
// in a self-contained HTML report plus the numbers as JSON and CSV
// (docs/ab-testing.md).
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <set>

#include "comparison.h"
#include "exit_codes.h"
#include "framework/graph_session.h"
#include "job_graph.h"
#include "job_pool.h"
#include "job_record.h"
#include "merge.h"
#include "options.h"
#include "output_layout.h"
#include "progress_bar.h"
#include "report_files.h"
#include "shard_manifest.h"
#include "stop_signals.h"
#include "tilth/log.h"
#include "tilth/version.h"

namespace tilth::ab {
namespace {

namespace fs = std::filesystem;

// Frames in flight per graph: enough to keep the chain's parallel stages busy while
// several graphs share the cores.
constexpr std::size_t kMaxInFlight = 4;

// One registry for every graph: the plugins next to each chain file and on the usual
// search path, and those the chains name.
std::unique_ptr<StageRegistry> plugins_for(const std::vector<Variant>& variants,
                                           const std::vector<fs::path>& named) {
  std::vector<fs::path> unique_named;
  std::set<std::string> seen;
  for (const auto& file : named) {
    if (seen.insert(fs::weakly_canonical(file).string()).second) unique_named.push_back(file);
  }
  auto registry = load_plugins(variants.front().chain.parent_path(), unique_named);
  for (const auto& variant : variants) {
    for (const auto& problem :
         registry->load_directories(plugin_search_path(variant.chain.parent_path()))) {
      log(LogLevel::kWarning, "plugins", problem);
    }
  }
  return registry;
}

// Problems appear once each, in the order found, however many jobs repeat them.
void print_problems(const Diagnostics& problems) {
  std::set<std::string> printed;
  for (const auto& item : problems.items()) {
    if (printed.insert(item.text()).second) std::cerr << item.text() << "\n";
  }
  std::cerr << printed.size() << " problem(s); nothing was run\n";
}

JobResult job_result(const JobRun& run, const JobFiles& files, const std::string& label,
                     double no_soil_below) {
  JobResult result;
  result.failed = run.failed;
  result.failure = run.failure;
  result.frames_per_second = run.metrics.frames_per_second;
  const std::string prefix = label + "/";
  for (const auto& stage : run.metrics.stages) {
    if (stage.node.starts_with(prefix)) {
      result.stages.push_back({stage.node.substr(prefix.size()), stage.type, stage.latency});
    }
  }
  read_job_frames(files, no_soil_below, result);
  return result;
}

// The graphs of the (variant, recording) jobs to run, variant-major: all, or a shard's.
// Nothing when a graph has problems (added to `problems`).
struct Jobs {
  std::vector<PreparedJob> graphs;
  std::vector<JobFiles> files;
  std::vector<std::string> labels;
  std::vector<std::size_t> indices;  // in the whole comparison: v * recordings + r
};

Jobs prepare_jobs(const Options& options, const StageRegistry& registry, Diagnostics& problems) {
  Jobs jobs;
  for (std::size_t v = 0; v < options.variants.size(); ++v) {
    const Variant& variant = options.variants[v];
    for (std::size_t r = 0; r < options.recordings.size(); ++r) {
      const Recording& recording = options.recordings[r];
      const std::size_t index = v * options.recordings.size() + r;
      if (options.shard && !options.shard->contains(index)) continue;
      const std::size_t before = problems.items().size();
      // Only the first variant saves the colour: the overlays show every mask over it.
      const JobOptions job_options{options.variables, kMaxInFlight, options.overlays > 0, v == 0};
      jobs.files.push_back(options.layout.job(variant.name, recording.name));
      jobs.labels.push_back(job_label(variant, recording));
      jobs.indices.push_back(index);
      // A shard run again replaces its own jobs' results, and only those.
      fs::remove_all(jobs.files.back().graph.parent_path());
      auto graph =
          job_graph(variant, recording, jobs.files.back(), job_options, registry, problems);
      if (graph) jobs.graphs.push_back({std::move(*graph), recording.frames});
      if (problems.items().size() > before) break;  // the other recordings would repeat it
    }
  }
  return jobs;
}

// A shard leaves its jobs' results and its manifest, for `tilth ab merge`.
int finish_shard(const Options& options, const Jobs& jobs, const std::vector<JobRun>& runs) {
  ShardManifest manifest{{},
                         *options.shard,
                         std::string(version()),
                         options.working_directory,
                         options.arguments,
                         comparison_identity(options),
                         jobs.indices};
  bool any_failed = false;
  for (std::size_t j = 0; j < runs.size(); ++j) {
    const JobResult result =
        job_result(runs[j], jobs.files[j], jobs.labels[j], options.no_soil_below);
    write_job_record(jobs.files[j], result);
    if (result.failed) std::cerr << "tilth ab: a graph failed: " << result.failure << "\n";
    any_failed = any_failed || result.failed;
  }
  write_shard_manifest(options.layout, manifest);
  if (!options.quiet) {
    std::printf("shard %s: %zu of the comparison's jobs in %s; 'tilth ab merge' makes the report\n",
                options.shard->text().c_str(), runs.size(), options.layout.dir.c_str());
  }
  return any_failed ? kExitFailed : kExitOk;
}

int run(Options options) {
  Diagnostics problems;
  std::vector<fs::path> named_plugins;
  for (auto& variant : options.variants) {
    const auto named = check_variant(variant, options.variables, problems);
    named_plugins.insert(named_plugins.end(), named.begin(), named.end());
  }
  if (!problems.empty()) {
    print_problems(problems);
    return kExitUsage;
  }
  const auto registry = plugins_for(options.variants, named_plugins);
  for (const auto& variant : options.variants) check_stage_types(variant, *registry, problems);
  if (!problems.empty()) {
    print_problems(problems);
    return kExitUsage;
  }
  try {
    if (options.shard) {
      prepare_shard_output(options.layout, *options.shard);
    } else {
      prepare_output(options.layout, options.overwrite);
    }
  } catch (const Error& error) {
    std::cerr << "tilth ab: --out " << error.what() << "\n";
    return kExitUsage;
  }
  Jobs jobs = prepare_jobs(options, *registry, problems);
  if (!problems.empty()) {
    print_problems(problems);
    std::error_code ignored;
    fs::remove_all(options.layout.runs(), ignored);
    return kExitUsage;
  }

  JobPool pool(*registry, options.jobs);
  std::vector<JobRun> runs;
  {
    const tools::StopSignalWatcher watcher("ab", [&pool] { pool.stop(); });
    std::optional<ProgressBar> bar;
    if (!options.quiet && isatty(STDOUT_FILENO) == 1) {
      bar.emplace([&pool] { return pool.progress(); });
    }
    runs = pool.run(std::move(jobs.graphs));
  }
  if (pool.stopped()) {
    std::cerr << "tilth ab: interrupted; no report written\n";
    return kExitFailed;
  }
  if (options.shard) return finish_shard(options, jobs, runs);
  Comparison comparison{options.variants,
                        options.recordings,
                        {},
                        options.no_soil_below,
                        options.baseline,
                        {command_line_of(options.arguments), options.working_directory, {}}};
  for (std::size_t j = 0; j < runs.size(); ++j) {
    comparison.jobs.push_back(
        job_result(runs[j], jobs.files[j], jobs.labels[j], options.no_soil_below));
  }
  const ReportFigures figures = report_figures(comparison);
  write_report(comparison, figures, options.layout, options.overlays);
  if (!options.keep_images) {
    for (const auto& files : jobs.files) fs::remove_all(files.images);
  }
  if (!options.quiet) print_summary(comparison, figures, options.layout);
  for (const auto& job : comparison.jobs) {
    if (job.failed) std::cerr << "tilth ab: a graph failed: " << job.failure << "\n";
  }
  return comparison.any_failed() ? kExitFailed : kExitOk;
}

}  // namespace
}  // namespace tilth::ab

int main(int argc, char** argv) {
  using namespace tilth::ab;
  tilth::tools::install_stop_handlers("ab");
  if (argc > 1 && std::string_view(argv[1]) == "merge") return merge_command(argc, argv);
  Options options;
  try {
    options = parse_options(argc, argv);
  } catch (const tilth::GraphError& error) {
    print_problems(error.diagnostics());
    return kExitUsage;
  } catch (const UsageError& error) {
    std::cerr << "tilth ab: " << error.what() << "\n\n" << kUsage;
    return kExitUsage;
  } catch (const tilth::Error& error) {
    std::cerr << "tilth ab: " << error.what() << "\n";
    return kExitUsage;
  }
  if (options.help) {
    std::cout << kUsage;
    return kExitOk;
  }
  tilth::set_log_level(options.verbose ? tilth::LogLevel::kDebug : tilth::LogLevel::kWarning);
  try {
    return run(std::move(options));
  } catch (const tilth::Error& error) {
    std::cerr << "tilth ab: " << error.what() << "\n";
    return kExitFailed;
  }
}
