// Fuzz target: a graph file's text through load_graph(), with a parameter and a
// variable set on the command line, as `tilth run --set --var` does. Every bad file must
// end in tilth::Error (the GraphError listing its problems); a crash, a sanitizer report
// or any other exception is a bug.
#include <cstddef>
#include <cstdint>

#include "framework/graph_loader.h"
#include "fuzz_input_file.h"
#include "tilth/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const tilth::GraphOverrides overrides{{{"estimate.min_soil_fraction", "0.2"}},
                                               {{"rate_hz", "25"}}};
  const auto file = tilth::fuzzing::write_input("graph.json", data, size);
  try {
    tilth::load_graph(file, overrides);
  } catch (const tilth::Error&) {
  }
  return 0;
}
