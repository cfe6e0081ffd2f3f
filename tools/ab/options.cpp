#include "options.h"

#include <algorithm>
#include <filesystem>
#include <thread>

#include "command_line.h"
#include "framework/install_layout.h"
#include "recording_tags.h"
#include "variant_specs.h"

namespace tilth::ab {

namespace fs = std::filesystem;

const char* const kUsage =
    R"(usage: tilth ab RECORDING... (--variant NAME[:SETTING] | --variants FILE)...
                [--out DIR] [options]
       tilth ab merge SHARD_DIR... --out DIR [--overwrite] [--quiet]

Replays each recording through each variant of the measurement chain (one graph per
variant and recording, several at once, as fast as they go) and compares the variants
with the recordings' ground truth: distance error, missed and false-valid frames, mask
IoU / precision / recall, time per stage. Writes DIR/report.html (self-contained),
summary.json, summary.csv, conditions.csv and frames.csv. docs/ab-testing.md explains every figure.
SIGINT or SIGTERM stops the graphs cleanly and writes no report (exit code 1); a second
signal exits at once (code 130).

'tilth ab merge' writes that report from the results that shards (--shard) left in each
SHARD_DIR, the same as one run would have written apart from timings, and lists the
jobs that no shard finished (exit code 1).

  RECORDING                 an image-folder recording (a folder with recording.json),
                            an .mcap file, or a folder holding several of them
  --variant NAME            a variant: the chain as it is ...
  --variant NAME:SETTING    ... changed by SETTING (repeat the NAME for more):
                              NODE.type=STAGE_TYPE  another stage type for a node
                              NODE.PARAM=VALUE      a parameter (VALUE as with --set)
                              chain=FILE            another chain graph file
                              recorded              no chain: what the machine measured,
                                                    as an MCAP recording holds it
                            e.g. --variant wide:segment.dilation_px=4
  --variants FILE           variants from a JSON file
  --chain FILE              the chain the variants change
                            (default: graphs/measurement-chain.json)
  --baseline NAME           the variant every other is paired with on the same frames
                            (default: the first)
  --tags FILE               recording tags (site, crop, ...) to break figures down by:
                            CSV with the header recording,KEY... (docs/ab-testing.md)
  --var NAME=VALUE          a graph variable for every graph, e.g. calibration=FILE
  --out DIR                 where the report goes (default: ab-report); missing or empty
  --overwrite               replace an earlier report in DIR
  --jobs N                  graphs run at once (default: the number of cores)
  --overlays N              frames per recording shown as mask overlays (default 3)
  --no-soil-below F         a frame whose truth mask is less than F soil has no visible
                            soil and must be reported invalid (default 0.01)
  --keep-images             keep every frame's saved masks and colour (DIR/runs/)
  --shard I/N               run only shard I of N of the (variant, recording) jobs
                            (job j is in shard j mod N) and leave their results in DIR
                            beside other shards'; no report: 'tilth ab merge' writes it
                            from every shard's DIR (docs/fleet.md)
  --quiet                   no progress bar and no summary
  --verbose                 debug log lines
)";

namespace {

// Each job holds a graph's frames in memory; more than this is no machine's core count.
constexpr std::uint64_t kMaxJobs = 256;
// Each overlay is an image embedded in the report page.
constexpr std::uint64_t kMaxOverlays = 100;

fs::path default_chain(const cli::CommandLine& line) {
  if (const auto chain = line.value("--chain")) {
    if (!fs::is_regular_file(*chain)) throw UsageError("--chain " + *chain + ": no such file");
    return fs::absolute(*chain).lexically_normal();
  }
  return shipped_data_dir() / "graphs" / "measurement-chain.json";
}

std::string variant_names(const std::vector<Variant>& variants) {
  std::string names;
  for (const auto& variant : variants) names += (names.empty() ? "" : ", ") + variant.name;
  return names;
}

}  // namespace

Options parse_options(int argc, char** argv) {
  const cli::CommandLine line(argc, argv, 1,
                              {"--variant", "--variants", "--chain", "--var", "--out", "--jobs",
                               "--overlays", "--no-soil-below", "--shard", "--baseline", "--tags"},
                              {"--help", "--overwrite", "--keep-images", "--quiet", "--verbose"});
  Options options;
  options.help = line.flag("--help");
  if (options.help) return options;
  options.verbose = line.flag("--verbose");
  if (line.positional().empty()) throw UsageError("no recording given");
  options.recordings = find_recordings(line.positional());
  const fs::path chain = default_chain(line);
  for (const auto& file : line.values("--variants")) {
    add_variants_from_file(file, chain, options.variants);
  }
  for (const auto& option : line.values("--variant")) {
    add_variant_option(option, chain, options.variants);
  }
  if (options.variants.empty()) throw UsageError("no variant given: use --variant or --variants");
  if (const auto baseline = line.value("--baseline")) {
    const auto found =
        std::find_if(options.variants.begin(), options.variants.end(),
                     [&](const Variant& variant) { return variant.name == *baseline; });
    if (found == options.variants.end()) {
      throw UsageError("--baseline " + *baseline + ": no such variant; the variants are " +
                       variant_names(options.variants));
    }
    options.baseline = static_cast<std::size_t>(found - options.variants.begin());
  }
  if (const auto tags = line.value("--tags")) apply_tags_file(*tags, options.recordings);
  for (const auto& variable : line.values("--var")) {
    options.variables.variables.push_back(parse_setting("--var", variable));
  }
  options.layout.dir = fs::absolute(line.value("--out").value_or("ab-report")).lexically_normal();
  options.overwrite = line.flag("--overwrite");
  try {
    options.jobs = line.count("--jobs", 1, kMaxJobs)
                       .value_or(std::max(1u, std::thread::hardware_concurrency()));
    options.overlays = line.count("--overlays", 0, kMaxOverlays).value_or(options.overlays);
    options.no_soil_below = line.real("--no-soil-below", 0.0, 1.0).value_or(options.no_soil_below);
  } catch (const Error& error) {
    throw UsageError(error.what());
  }
  options.keep_images = line.flag("--keep-images");
  if (const auto shard = line.value("--shard")) {
    try {
      options.shard = parse_shard(*shard);
    } catch (const Error& error) {
      throw UsageError(error.what());
    }
  }
  options.arguments.assign(argv + 1, argv + argc);
  options.working_directory = fs::current_path();
  options.quiet = line.flag("--quiet");
  return options;
}

}  // namespace tilth::ab
