// Loading and validating a graph costs the same per node at 2 000 nodes as at 20 000.
// Counted, not timed: the heap allocations of load_graph + validate_graph, which grew
// with nodes x edges while each edge's endpoints were looked up through a fresh list of
// every node's name (20 000 nodes took over 30 s). This executable counts every
// allocation, so it holds nothing else.
#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include <gtest/gtest.h>

#include "framework/graph_loader.h"
#include "framework/graph_validator.h"
#include "temp_dir.h"
#include "test_stages.h"

namespace {
std::atomic<std::size_t> allocations{0};
}  // namespace

// Counts and allocates as libstdc++'s own operator new does (malloc), so its operator
// delete (free) stays the right one to release it.
void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* memory = std::malloc(size == 0 ? 1 : size)) return memory;
  throw std::bad_alloc();
}

namespace tilth {
namespace {

// `pairs` sources, each feeding its own sink; names longer than std::string keeps
// inline, so that every copy of a name allocates.
std::string pairs_graph(int pairs) {
  std::string nodes;
  std::string edges;
  for (int i = 0; i < pairs; ++i) {
    const std::string n = std::to_string(i);
    nodes += (i ? ",\n" : "") + std::string("\"soil_sensor_source_") + n +
             "\": {\"type\": \"test.counter\"}, \"recording_sink_number_" + n +
             "\": {\"type\": \"test.record\"}";
    edges += (i ? ",\n" : "") + std::string("[\"soil_sensor_source_") + n +
             ".out\", \"recording_sink_number_" + n + ".in\"]";
  }
  return "{\"nodes\": {" + nodes + "},\n\"edges\": [" + edges + "]}";
}

// Allocations per node to load and validate a graph of 2 * `pairs` nodes.
double allocations_per_node(int pairs) {
  testing::TempDir dir;
  const auto file = dir.write("g.json", pairs_graph(pairs));
  StageRegistry registry;
  testing::register_test_stages(registry);
  const std::size_t before = allocations.load();
  const ValidatedGraph graph = validate_graph(load_graph(file), registry);
  const std::size_t used = allocations.load() - before;
  EXPECT_EQ(graph.nodes.size(), 2u * pairs);
  return static_cast<double>(used) / (2.0 * pairs);
}

TEST(GraphScaling, CostPerNodeDoesNotGrowWithTheGraph) {
  const double small = allocations_per_node(1'000);
  const double large = allocations_per_node(10'000);
  RecordProperty("allocations_per_node_at_2000", std::to_string(small));
  RecordProperty("allocations_per_node_at_20000", std::to_string(large));
  // Linear: the same per node, give or take the containers' geometric growth. The
  // quadratic lookup made it 10 times larger.
  EXPECT_LT(large, 1.2 * small) << small << " allocations per node at 2 000 nodes, " << large
                                << " at 20 000";
  EXPECT_LT(large, 200.0);
}

}  // namespace
}  // namespace tilth
