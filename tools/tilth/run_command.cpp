// `tilth run`: runs a graph until its sources end, --frames is reached, or SIGINT /
// SIGTERM asks it to stop (frames in flight finish, sinks flush, exit code 0; 3 when a
// stage lost data). Started by systemd (Type=notify), it reports readiness and progress.
#include <csignal>
#include <iostream>

#include <unistd.h>

#include "command_line.h"
#include "commands.h"
#include "data_loss_report.h"
#include "framework/diagnostics.h"
#include "framework/graph_session.h"
#include "framework/runtime.h"
#include "graph_options.h"
#include "journal_log.h"
#include "service_notifier.h"
#include "status_reporter.h"
#include "stop_signals.h"
#include "tilth/log.h"

namespace tilth::cli {
namespace {

const std::string kUsage =
    std::string(
        "usage: tilth run GRAPH [--set NODE.PARAM=VALUE]... [--var NAME=VALUE]... [--frames N]\n"
        "                 [--quiet] [--verbose]\n\n"
        "Runs a graph. Ctrl-C (SIGINT) or SIGTERM stops it cleanly: frames in flight\n"
        "finish and sinks flush; a second signal exits at once (code 130). At the end each\n"
        "stage's latency and the graph's frame rate are printed.\n\n"
        "Exit code 0 success, 1 the run failed, 2 bad usage or an invalid graph, 3 the run\n"
        "ended but a stage could not store data (a full disk; each such stage is named).\n\n") +
    kGraphOptionsHelp +
    "  --frames N              stop after N frames\n"
    "  --quiet                 warnings and errors only: no info lines, status line or summary\n"
    "  --verbose               debug log lines\n";

// A year at 30 frames/s is 1e9 frames; a thousand times that is no typing slip.
constexpr std::uint64_t kMaxFrames = 1'000'000'000'000;

}  // namespace

int run_command(int argc, char** argv) {
  tools::install_stop_handlers("run");
  // A closed standard output (`tilth run ... | head -1`) makes writes fail with EPIPE,
  // which sinks.console answers by ending the run cleanly, instead of killing the
  // process with files half written.
  std::signal(SIGPIPE, SIG_IGN);

  const CommandLine line(argc, argv, 2, {"--set", "--var", "--frames"},
                         {"--help", "--quiet", "--verbose"});
  if (line.flag("--help")) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (line.positional().size() != 1) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  if (stderr_is_journal()) log_to_journal();
  if (line.flag("--verbose")) set_log_level(LogLevel::kDebug);
  if (line.flag("--quiet")) set_log_level(LogLevel::kWarning);
  RunLimits limits;
  limits.max_frames = line.count("--frames", 1, kMaxFrames);
  const std::string file = line.positional()[0];
  GraphSession session;
  try {
    session = open_graph(file, graph_overrides(line));
  } catch (const GraphError& error) {
    std::cerr << error.what() << "\n"
              << error.diagnostics().items().size() << " problem(s); nothing was run\n";
    return kExitUsage;
  }
  std::unique_ptr<Runtime> runtime;
  try {
    runtime = std::make_unique<Runtime>(std::move(session.graph), *session.registry, limits);
  } catch (const Error& error) {
    std::cerr << file << ": " << error.what() << "\n";
    return kExitFailed;
  }
  log(LogLevel::kInfo, "run", "running " + file);
  RunResult result;
  {
    std::optional<ServiceNotifier> service;
    if (ServiceNotifier::wanted()) service.emplace([&runtime] { return runtime->metrics(); });
    const tools::StopSignalWatcher watcher("run", [&runtime, &service] {
      if (service) service->stopping();
      runtime->stop();
    });
    std::optional<StatusReporter> reporter;
    if (!line.flag("--quiet")) {
      reporter.emplace([&runtime] { return runtime->metrics(); }, isatty(STDERR_FILENO) == 1);
    }
    result = runtime->run();
  }
  if (!line.flag("--quiet")) std::cerr << metrics_report(result.metrics);
  std::cerr << tools::data_loss_report("tilth run", result.data_lost);
  if (result.failed) {
    std::cerr << "tilth run: " << result.failure << "\n";
    return kExitFailed;
  }
  return result.data_lost.empty() ? kExitOk : kExitDataLost;
}

}  // namespace tilth::cli
