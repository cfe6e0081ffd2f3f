// Validation before anything runs: each kind of problem, with its exact message.
#include "framework/graph_validator.h"

#include <gtest/gtest.h>

#include "framework/diagnostics.h"
#include "framework/graph_loader.h"
#include "framework/runtime.h"
#include "temp_dir.h"
#include "test_stages.h"
#include "tilth/messages/depth_image.h"

namespace tilth {
namespace {

using testing::TempDir;

class GraphValidatorTest : public ::testing::Test {
 protected:
  GraphValidatorTest() : file_(dir_.path() / "g.json") {
    testing::register_test_stages(registry_);
    StageDescriptor depth_sink;
    depth_sink.type = "test.depth_sink";
    depth_sink.summary = "takes depth images";
    depth_sink.inputs = {PortSpec::of<DepthImage>("depth", "depth in mm")};
    depth_sink.create = [](const StageContext&) -> std::unique_ptr<Stage> { return nullptr; };
    registry_.add(depth_sink, "test");
  }

  // The validation errors for a graph file with this text, or "valid".
  std::string errors(const std::string& text, const GraphOverrides& overrides = {}) {
    dir_.write("g.json", text);
    try {
      validate_graph(load_graph(file_, overrides), registry_);
    } catch (const GraphError& error) {
      return error.what();
    }
    return "valid";
  }
  std::string at(const std::string& pointer) const { return file_.string() + ":" + pointer; }

  TempDir dir_;
  std::filesystem::path file_;
  StageRegistry registry_;
};

TEST_F(GraphValidatorTest, AcceptsAGoodGraphInTopologicalOrder) {
  file_ = dir_.write("g.json", R"({
    "nodes": {"out": {"type": "test.record"},
              "sum": {"type": "test.add"},
              "d": {"type": "test.delay"},
              "src": {"type": "test.counter", "params": {"count": 3}}},
    "edges": [["sum.sum", "out.in"], ["src.out", "sum.a"], ["d.out", "sum.b"], ["src.out", "d.in"]]
  })");
  const ValidatedGraph graph = validate_graph(load_graph(file_), registry_);
  std::vector<std::string> order;
  for (const auto& node : graph.nodes) order.push_back(node.name);
  EXPECT_EQ(order, (std::vector<std::string>{"src", "d", "sum", "out"}));
  EXPECT_EQ(graph.nodes[0].successors, (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(graph.nodes[2].inputs[0]->node, 0u);
  EXPECT_EQ(graph.nodes[2].inputs[1]->node, 1u);
  EXPECT_EQ(graph.nodes[0].params.integer("count"), 3);
  EXPECT_EQ(graph.nodes[3].params.string("mode"), "fast");  // the default
}

TEST_F(GraphValidatorTest, UnknownStageTypeSuggestsNearestNames) {
  EXPECT_EQ(errors(R"({"nodes": {"src": {"type": "test.countr"}}})"),
            at("/nodes/src/type") +
                ": unknown stage type 'test.countr'; did you mean "
                "'test.counter'?\n" +
                file_.string() + ": the graph has no source stage");
  EXPECT_EQ(errors(R"({"nodes": {"src": {"type": "test.counter"}, "x": {"type": "zzz"}}})"),
            at("/nodes/x/type") +
                ": unknown stage type 'zzz' (run 'tilth plugins' to list the known types)");
}

TEST_F(GraphValidatorTest, UnknownPortListsThePorts) {
  EXPECT_EQ(errors(R"({"nodes": {"src": {"type": "test.counter"}, "out": {"type": "test.record"}},
                       "edges": [["src.ot", "out.in"]]})"),
            at("/edges/0") +
                ": node 'src' (test.counter) has no output port 'ot'; did you mean "
                "'out'?; its outputs: 'out'\n" +
                at("/nodes/out") + ": input 'in' (test.Count) is not connected");
}

TEST_F(GraphValidatorTest, EdgeEndpointsAreChecked) {
  EXPECT_EQ(errors(R"({"nodes": {"src": {"type": "test.counter"}, "out": {"type": "test.record"}},
                       "edges": [["src", "out.in"], ["scr.out", "out.in"]]})"),
            at("/edges/0") + ": expected \"NODE.PORT\", got \"src\"\n" + at("/edges/1") +
                ": no node named 'scr'; did you mean 'src'?\n" + at("/nodes/out") +
                ": input 'in' (test.Count) is not connected");
}

TEST_F(GraphValidatorTest, TypeMismatchOnAnEdge) {
  EXPECT_EQ(errors(R"({"nodes": {"src": {"type": "test.counter"}, "d": {"type": "test.depth_sink"}},
                       "edges": [["src.out", "d.depth"]]})"),
            at("/edges/0") +
                ": type mismatch: src.out carries test.Count but d.depth expects "
                "tilth.DepthImage\n" +
                at("/nodes/d") + ": input 'depth' (tilth.DepthImage) is not connected");
}

TEST_F(GraphValidatorTest, InputFedTwice) {
  EXPECT_EQ(errors(R"({"nodes": {"a": {"type": "test.counter"}, "b": {"type": "test.counter"},
                                 "out": {"type": "test.record"}},
                       "edges": [["a.out", "out.in"], ["b.out", "out.in"]]})"),
            at("/edges/1") + ": input out.in is already fed by a.out (" + at("/edges/0") + ")");
}

TEST_F(GraphValidatorTest, SynchronizerInputsComeStraightFromSourcesThatFeedNothingElse) {
  EXPECT_EQ(errors(R"({"nodes": {"a": {"type": "test.counter"}, "b": {"type": "test.counter"},
                                 "d": {"type": "test.delay"}, "pair": {"type": "test.pair_equal"},
                                 "out": {"type": "test.record"}, "raw": {"type": "test.record"}},
                       "edges": [["a.out", "d.in"], ["d.out", "pair.a"], ["b.out", "pair.b"],
                                 ["b.out", "raw.in"], ["pair.sum", "out.in"]]})"),
            at("/edges/1") +
                ": pair.a belongs to synchronizer 'pair', whose inputs must come straight from "
                "sources; 'd' is a transform\n" +
                at("/edges/3") +
                ": source 'b' feeds synchronizer 'pair', so it enters the graph there and can "
                "feed nothing else; connect 'raw' to the synchronizer's outputs");
}

TEST_F(GraphValidatorTest, CycleIsNamed) {
  EXPECT_EQ(errors(R"({"nodes": {"src": {"type": "test.counter"}, "sum": {"type": "test.add"},
                                 "d": {"type": "test.delay"}, "out": {"type": "test.record"}},
                       "edges": [["src.out", "sum.a"], ["d.out", "sum.b"], ["sum.sum", "d.in"],
                                 ["sum.sum", "out.in"]]})"),
            at("/nodes/d") + ": the graph has a cycle: d -> sum -> d");
}

TEST_F(GraphValidatorTest, ParametersAreChecked) {
  EXPECT_EQ(
      errors(R"({"nodes": {"src": {"type": "test.counter", "params": {"cont": 3, "period_us": -1}},
                           "out": {"type": "test.record",
                                   "params": {"gain": 11, "mode": "slow", "delay_us": 1.5}},
                           "p": {"type": "test.needs_path"}},
                 "edges": [["src.out", "out.in"], ["src.out", "p.in"]]})"),
      at("/nodes/src/params/cont") +
          ": unknown parameter 'cont' of test.counter; did you mean 'count'? (its parameters: "
          "'count', 'period_us', 'start_delay_us', 'step')\n" +
          at("/nodes/src/params/period_us") +
          ": parameter 'period_us': expected an integer >= 0, got -1\n" +
          at("/nodes/out/params/delay_us") +
          ": parameter 'delay_us': expected an integer >= 0, got 1.5\n" +
          at("/nodes/out/params/gain") +
          ": parameter 'gain': expected a number in [0, 10], got 11\n" +
          at("/nodes/out/params/mode") +
          ": parameter 'mode': expected one of 'fast', 'exact', got \"slow\"\n" + at("/nodes/p") +
          ": missing required parameter 'file' (path: a file to read)");
}

TEST_F(GraphValidatorTest, OutputPathsAreRelativeToTheWorkingDirectoryInputPathsToTheFile) {
  file_ = dir_.write("g.json", R"({"nodes": {"src": {"type": "test.counter"},
                                            "out": {"type": "test.record",
                                                    "params": {"file": "in/x.txt", "log": "out/y.csv"}}},
                                  "edges": [["src.out", "out.in"]]})");
  const ValidatedGraph graph = validate_graph(load_graph(file_), registry_);
  EXPECT_EQ(graph.nodes[1].params.path("file"), dir_.path() / "in/x.txt");
  EXPECT_EQ(graph.nodes[1].params.path("log"), std::filesystem::current_path() / "out/y.csv");

  const ValidatedGraph defaults =
      validate_graph(load_graph(dir_.write("d.json", R"({"nodes": {"src": {"type": "test.counter"},
                                                    "out": {"type": "test.record"}},
                                          "edges": [["src.out", "out.in"]]})")),
                     registry_);
  EXPECT_EQ(defaults.nodes[1].params.path("log"), "record.log");  // defaults stay as declared

  GraphOverrides absolute;
  absolute.params = {{"out.log", "/var/lib/tilth/seeder.csv"}};
  EXPECT_EQ(validate_graph(load_graph(file_, absolute), registry_).nodes[1].params.path("log"),
            "/var/lib/tilth/seeder.csv");
}

TEST_F(GraphValidatorTest, CommandLineValuesTakeTheParameterType) {
  file_ = dir_.write("g.json", R"({"nodes": {"src": {"type": "test.counter"},
                                            "out": {"type": "test.record", "params": {"file": "rel/x.txt"}}},
                                  "edges": [["src.out", "out.in"]]})");
  const ValidatedGraph from_file = validate_graph(load_graph(file_), registry_);
  EXPECT_EQ(from_file.nodes[1].params.path("file"), dir_.path() / "rel/x.txt");

  GraphOverrides overrides;
  overrides.params = {{"out.file", "123"}, {"out.mode", "exact"}, {"src.count", "4"}};
  const ValidatedGraph graph = validate_graph(load_graph(file_, overrides), registry_);
  EXPECT_EQ(graph.nodes[1].params.path("file"), std::filesystem::current_path() / "123");
  EXPECT_EQ(graph.nodes[0].params.integer("count"), 4);

  EXPECT_EQ(
      errors(R"({"nodes": {"src": {"type": "test.counter"}}})", {{{"src.count", "many"}}, {}}),
      "command line:--set src.count: parameter 'count': expected an integer >= 0, got \"many\"");
}

// A sub-graph file: two inputs and an output on its boundary, one more input fed inside.
constexpr const char* kFragment = R"({
  "inputs": {"left": "sum.a", "right": "sum.b"},
  "outputs": {"total": "sum.sum"},
  "nodes": {"sum": {"type": "test.add"}, "out": {"type": "test.record"}},
  "edges": [["sum.sum", "out.in"]]
})";

TEST_F(GraphValidatorTest, AFragmentValidatesOnItsOwnWithItsInputsOpen) {
  dir_.write("g.json", kFragment);
  const ValidatedGraph graph = validate_graph(load_graph(file_), registry_);
  EXPECT_EQ(graph.open_inputs, (std::vector<std::string>{"left (sum.a)", "right (sum.b)"}));
  EXPECT_EQ(graph.outputs, (std::vector<std::string>{"total (sum.sum)"}));
  EXPECT_EQ(graph.nodes.size(), 2u);
}

TEST_F(GraphValidatorTest, AFragmentStillReportsItsOtherProblems) {
  EXPECT_EQ(errors(R"({"inputs": {"left": "sum.a"},
                       "nodes": {"sum": {"type": "test.add"}, "out": {"type": "test.record"}},
                       "edges": [["sum.sum", "out.in"]]})"),
            at("/nodes/sum") + ": input 'b' (test.Count) is not connected");
  EXPECT_EQ(errors(R"({"inputs": {"left": "sum.sum", "right": "sum.b", "x": "nothing.in"},
                       "outputs": {"total": "sum.a"},
                       "nodes": {"sum": {"type": "test.add"}, "out": {"type": "test.record"}},
                       "edges": [["sum.sum", "out.in"]]})"),
            at("/inputs/left") +
                ": node 'sum' (test.add) has no input port 'sum'; its inputs: 'a', 'b'\n" +
                at("/inputs/x") + ": no node named 'nothing'\n" + at("/outputs/total") +
                ": node 'sum' (test.add) has no output port 'a'; its outputs: 'sum'\n" +
                at("/nodes/sum") + ": input 'a' (test.Count) is not connected");
  EXPECT_EQ(errors(R"({"inputs": ["sum.a"], "outputs": {"total": 3},
                       "nodes": {"src": {"type": "test.counter"}}})"),
            at("/inputs") + ": expected an object of name: \"node.port\"\n" + at("/outputs/total") +
                ": expected \"node.port\", got 3");
}

TEST_F(GraphValidatorTest, AnIncludedFragmentsInputsMustBeFed) {
  dir_.write("fragment.json", kFragment);
  const std::string include = R"("include": [{"file": "fragment.json", "as": "f"}],
    "nodes": {"src": {"type": "test.counter"}},)";
  EXPECT_EQ(errors("{" + include + R"("edges": [["src.out", "f/sum.a"]]})"),
            (dir_.path() / "fragment.json").string() +
                ":/nodes/sum: input 'b' (test.Count) is not connected");
  dir_.write("g.json",
             "{" + include + R"("edges": [["src.out", "f/sum.a"], ["src.out", "f/sum.b"]]})");
  const ValidatedGraph graph = validate_graph(load_graph(file_), registry_);
  EXPECT_TRUE(graph.open_inputs.empty());
  EXPECT_TRUE(graph.outputs.empty());  // the included file's, not this graph's
}

TEST_F(GraphValidatorTest, AFragmentCannotRun) {
  dir_.write("g.json", kFragment);
  try {
    Runtime runtime(validate_graph(load_graph(file_), registry_), registry_);
    FAIL() << "a fragment ran";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "a fragment: nothing feeds its inputs 'left (sum.a)', 'right (sum.b)'; run a graph "
              "that includes it and feeds them (docs/graph-format.md)");
  }
}

}  // namespace
}  // namespace tilth
