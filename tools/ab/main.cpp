// `tilth ab`: replays recordings through variants of the measurement chain, one graph
// per (variant, recording), several at once, and compares them with the ground truth
// in a self-contained HTML report plus the numbers as JSON and CSV
// (docs/ab-testing.md).
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <set>

#include "comparison.h"
#include "framework/graph_session.h"
#include "job_graph.h"
#include "job_pool.h"
#include "options.h"
#include "output_layout.h"
#include "overlays.h"
#include "progress_bar.h"
#include "report_html.h"
#include "report_numbers.h"
#include "stop_signals.h"
#include "tilth/log.h"

namespace tilth::ab {
namespace {

namespace fs = std::filesystem;

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;
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
  if (fs::exists(files.frames)) {
    result.frames = judge_frames(read_frame_records(files.frames), no_soil_below);
  }
  return result;
}

std::string column(const std::optional<double>& value, const char* format) {
  if (!value) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, *value);
  return text;
}

void print_summary(const Comparison& comparison, const OutputLayout& layout) {
  std::printf("%-24s %7s %7s %7s %7s %12s %12s %7s\n", "variant", "frames", "valid", "missed",
              "f.valid", "mean|err|mm", "max|err|mm", "IoU");
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    const Figures f = comparison.variant_figures(v);
    const bool errors = f.error.count > 0;
    std::printf("%-24s %7zu %7zu %7zu %7zu %12s %12s %7s\n", comparison.variants[v].name.c_str(),
                f.frames, f.valid, f.missed, f.false_valid,
                column(errors ? std::optional(f.error.mean_abs_mm) : std::nullopt, "%.3f").c_str(),
                column(errors ? std::optional(f.error.max_abs_mm) : std::nullopt, "%.3f").c_str(),
                column(f.mask ? f.mask->iou() : std::nullopt, "%.3f").c_str());
  }
  std::printf("report: %s\n", layout.report().c_str());
}

// The graphs of every (variant, recording) job, variant-major, or nothing when a graph has
// problems (added to `problems`).
struct Jobs {
  std::vector<PreparedJob> graphs;
  std::vector<JobFiles> files;
  std::vector<std::string> labels;
};

Jobs prepare_jobs(const Options& options, const StageRegistry& registry, Diagnostics& problems) {
  Jobs jobs;
  for (std::size_t v = 0; v < options.variants.size(); ++v) {
    const Variant& variant = options.variants[v];
    for (const auto& recording : options.recordings) {
      const std::size_t before = problems.items().size();
      // Only the first variant saves the colour: the overlays show every mask over it.
      const JobOptions job_options{options.variables, kMaxInFlight, options.overlays > 0, v == 0};
      jobs.files.push_back(options.layout.job(variant.name, recording.name));
      jobs.labels.push_back(job_label(variant, recording));
      auto graph =
          job_graph(variant, recording, jobs.files.back(), job_options, registry, problems);
      if (graph) jobs.graphs.push_back({std::move(*graph), recording.frames});
      if (problems.items().size() > before) break;  // the other recordings would repeat it
    }
  }
  return jobs;
}

void write_outputs(const Comparison& comparison, const Options& options) {
  Overlays overlays;
  for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
    overlays.push_back(disagreement_overlays(comparison, options.layout, r, options.overlays));
  }
  const auto summary = summary_json(comparison, overlays);
  write_text(options.layout.summary_json(), summary.dump(2) + "\n");
  write_summary_csv(comparison, options.layout.summary_csv());
  write_frames_csv(comparison, options.layout.frames_csv());
  write_text(options.layout.report(), report_html(comparison, summary, overlays));
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
    prepare_output(options.layout, options.overwrite);
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
  Comparison comparison{options.variants, options.recordings, {}, options.no_soil_below};
  for (std::size_t j = 0; j < runs.size(); ++j) {
    comparison.jobs.push_back(
        job_result(runs[j], jobs.files[j], jobs.labels[j], options.no_soil_below));
  }
  write_outputs(comparison, options);
  if (!options.keep_images) {
    for (const auto& files : jobs.files) fs::remove_all(files.images);
  }
  if (!options.quiet) print_summary(comparison, options.layout);
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
