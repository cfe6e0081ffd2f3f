// The command line of `tilth ab`: the recordings, the variants and how to compare them.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "framework/graph_loader.h"
#include "output_layout.h"
#include "recording_list.h"
#include "shard.h"
#include "tilth/error.h"
#include "variant.h"

namespace tilth::ab {

extern const char* const kUsage;

struct Options {
  std::vector<Recording> recordings;
  std::vector<Variant> variants;
  std::size_t baseline = 0;  // the variant the others are paired with (--baseline)
  GraphOverrides variables;  // --var
  OutputLayout layout;
  bool overwrite = false;
  std::size_t jobs = 1;
  std::size_t overlays = 3;
  double no_soil_below = 0.01;
  bool keep_images = false;
  std::optional<Shard> shard;               // run only these jobs, leave their results for a merge
  std::vector<std::string> arguments;       // as given, for a shard's manifest
  std::filesystem::path working_directory;  // where they were given
  bool quiet = false;
  bool verbose = false;
  bool help = false;
};

// A mistake on the command line (exit code 2, with the usage).
class UsageError : public Error {
 public:
  using Error::Error;
};

// Throws UsageError, tilth::Error (a recording or variant that is not right) or
// GraphError (a variants file's problems).
Options parse_options(int argc, char** argv);

}  // namespace tilth::ab
