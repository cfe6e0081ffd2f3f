// Graph files: includes, variables, overrides, and the exact error for each way a file
// can be wrong.
#include "framework/graph_loader.h"

#include <gtest/gtest.h>

#include "framework/diagnostics.h"
#include "temp_dir.h"

namespace tilth {
namespace {

using testing::TempDir;

std::string load_error(const std::filesystem::path& file, const GraphOverrides& overrides = {}) {
  try {
    load_graph(file, overrides);
  } catch (const GraphError& error) {
    return error.what();
  }
  return "no error";
}

const NodeSpec& node(const GraphSpec& graph, const std::string& name) {
  for (const auto& n : graph.nodes) {
    if (n.name == name) return n;
  }
  throw Error("no node " + name);
}

TEST(GraphLoader, ReadsNodesEdgesAndRuntime) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({
    "description": "two nodes",
    "nodes": {"src": {"type": "test.counter", "params": {"count": 5}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "out.in"]],
    "runtime": {"max_in_flight": 2, "when_full": "drop_oldest", "on_error": "stop"}
  })");
  const GraphSpec graph = load_graph(file);
  EXPECT_EQ(graph.description, "two nodes");
  ASSERT_EQ(graph.nodes.size(), 2u);
  EXPECT_EQ(node(graph, "src").params.at("count").value, 5);
  EXPECT_EQ(node(graph, "src").params.at("count").where.text(),
            file.string() + ":/nodes/src/params/count");
  ASSERT_EQ(graph.edges.size(), 1u);
  EXPECT_EQ(graph.edges[0].from, "src.out");
  EXPECT_EQ(graph.edges[0].to, "out.in");
  EXPECT_EQ(graph.runtime.max_in_flight, 2u);
  EXPECT_EQ(graph.runtime.when_full, FullPolicy::kDropOldest);
  EXPECT_EQ(graph.runtime.on_error, ErrorPolicy::kStop);
}

TEST(GraphLoader, MalformedJsonGivesLineAndColumn) {
  TempDir dir;
  const auto file =
      dir.write("bad.json", "{\n  \"nodes\": {\n    \"a\": {\"type\": \"x\",}\n  }\n}\n");
  EXPECT_EQ(load_error(file),
            file.string() +
                ":3:23: malformed JSON: syntax error while parsing object key - unexpected '}'; "
                "expected string literal");
}

TEST(GraphLoader, MissingFileIsReported) {
  EXPECT_EQ(load_error("/nonexistent/g.json"),
            "/nonexistent/g.json: cannot read graph file "
            "'/nonexistent/g.json'");
}

TEST(GraphLoader, IncludesAreNamespacedAndOverridable) {
  TempDir dir;
  dir.write("chain.json", R"({
    "variables": {"gain": 1.0},
    "nodes": {"delay": {"type": "test.delay", "params": {"add": "${gain}"}},
              "out": {"type": "test.record", "params": {"mode": "fast"}}},
    "edges": [["delay.out", "out.in"]]
  })");
  const auto file = dir.write("machine.json", R"({
    "include": [{"file": "chain.json", "as": "chain", "variables": {"gain": 3}}],
    "nodes": {"src": {"type": "test.counter"},
              "chain/out": {"params": {"mode": "exact"}}},
    "edges": [["src.out", "chain/delay.in"]]
  })");
  const GraphSpec graph = load_graph(file);
  ASSERT_EQ(graph.nodes.size(), 3u);
  EXPECT_EQ(node(graph, "chain/delay").params.at("add").value, 3);
  EXPECT_EQ(node(graph, "chain/out").type, "test.record");
  EXPECT_EQ(node(graph, "chain/out").params.at("mode").value, "exact");
  EXPECT_EQ(node(graph, "chain/out").params.at("mode").where.text(),
            file.string() + ":/nodes/chain~1out/params/mode");
  ASSERT_EQ(graph.edges.size(), 2u);
  EXPECT_EQ(graph.edges[0].from, "chain/delay.out");
  EXPECT_EQ(graph.edges[1].to, "chain/delay.in");
}

TEST(GraphLoader, NodeWithTypeReplacesIncludedNode) {
  TempDir dir;
  dir.write("base.json", R"({"nodes": {"src": {"type": "test.counter", "params": {"count": 9}}}})");
  const auto file = dir.write("g.json", R"({
    "include": ["base.json"],
    "nodes": {"src": {"type": "test.other"}}
  })");
  const GraphSpec graph = load_graph(file);
  ASSERT_EQ(graph.nodes.size(), 1u);
  EXPECT_EQ(graph.nodes[0].type, "test.other");
  EXPECT_TRUE(graph.nodes[0].params.empty());
}

// An override file swaps the cameras of a machine graph for a simulator: null removes
// an included node, its edges and the inputs and outputs on it; the new node is wired in
// its place.
TEST(GraphLoader, NullRemovesAnIncludedNodeWithItsEdges) {
  TempDir dir;
  dir.write("machine.json", R"({
    "nodes": {"cam": {"type": "test.camera"}, "pair": {"type": "test.pair"},
              "chain": {"type": "test.chain"}},
    "edges": [["cam.image", "pair.image"], ["pair.image", "chain.in"]],
    "inputs": {"frames": "chain.in"}, "outputs": {"paired": "pair.image", "result": "chain.out"}
  })");
  const auto file = dir.write("g.json", R"({
    "include": ["machine.json"],
    "nodes": {"cam": null, "pair": null, "sim": {"type": "test.sim"}},
    "edges": [["sim.raw", "chain.in"]]
  })");
  const GraphSpec graph = load_graph(file);
  ASSERT_EQ(graph.nodes.size(), 2u);
  EXPECT_EQ(graph.nodes[0].name, "chain");
  EXPECT_EQ(graph.nodes[1].name, "sim");
  ASSERT_EQ(graph.edges.size(), 1u);
  EXPECT_EQ(graph.edges[0].from, "sim.raw");
  ASSERT_EQ(graph.inputs.size(), 1u);  // the removed node's output left with it
  EXPECT_EQ(graph.inputs[0].endpoint, "chain.in");
  EXPECT_FALSE(graph.inputs[0].top_level);
  ASSERT_EQ(graph.outputs.size(), 1u);
  EXPECT_EQ(graph.outputs[0].name, "result");

  const auto wrong =
      dir.write("h.json", R"({"include": ["machine.json"], "nodes": {"cma": null}})");
  EXPECT_EQ(load_error(wrong), wrong.string() +
                                   ":/nodes/cma: null removes an included node, but there is no "
                                   "node 'cma'; did you mean 'cam'?");
}

TEST(GraphLoader, CommandLineOverridesParamsVariablesAndRuntime) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({
    "variables": {"n": 4, "name": "run"},
    "nodes": {"src": {"type": "test.counter", "params": {"count": "${n}"}},
              "out": {"type": "test.record", "params": {"file": "${name}-${n}.txt"}}}
  })");
  GraphOverrides overrides;
  overrides.variables = {{"n", "7"}};
  overrides.params = {{"out.file", "x.csv"}, {"runtime.max_in_flight", "8"}, {"src.count", "12"}};
  const GraphSpec graph = load_graph(file, overrides);
  EXPECT_EQ(node(graph, "src").params.at("count").value, 12);
  EXPECT_EQ(node(graph, "out").params.at("file").value, "x.csv");
  EXPECT_EQ(node(graph, "out").params.at("file").base_dir, std::filesystem::current_path());
  EXPECT_EQ(graph.runtime.max_in_flight, 8u);

  const GraphSpec with_vars = load_graph(file, {{}, {{"n", "7"}}});
  EXPECT_EQ(node(with_vars, "out").params.at("file").value, "run-7.txt");
  EXPECT_EQ(node(with_vars, "src").params.at("count").value, 7);
  // The path starts with the file's own variable: relative to the file's directory.
  EXPECT_EQ(node(with_vars, "out").params.at("file").base_dir, file.parent_path());
}

TEST(GraphLoader, ACommandLineVariableNoFileDeclaresIsAnError) {
  TempDir dir;
  const auto chain = dir.write("chain.json", R"({
    "variables": {"calibration": ""},
    "nodes": {"in": {"type": "test.record", "params": {"file": "${calibration}"}}}
  })");
  const auto file = dir.write("machine.json", R"({
    "variables": {"plc_address": "192.168.10.2"},
    "include": [{"file": "chain.json", "as": "chain"}],
    "nodes": {"src": {"type": "test.counter", "params": {"count": 1}}}
  })");
  // Declared in the included file: accepted.
  EXPECT_NO_THROW(load_graph(file, {{}, {{"calibration", "rig.json"}}}));
  EXPECT_EQ(load_error(file, {{}, {{"plc_adress", "10.0.0.2"}}}),
            "command line:--var plc_adress: no file of the graph declares a variable "
            "'plc_adress'; did you mean 'plc_address'? (declared: 'calibration', "
            "'plc_address')");
}

// `--var log=run.csv` names a file where the user typed it, as `--set` does.
TEST(GraphLoader, APathStartingWithACommandLineVariableIsRelativeToTheWorkingDirectory) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({
    "variables": {"log": "default.csv", "folder": "logs"},
    "nodes": {"src": {"type": "test.counter"},
              "out": {"type": "test.record", "params": {"file": "${log}"}},
              "also": {"type": "test.record", "params": {"file": "${folder}/${log}"}}}
  })");
  const GraphSpec defaults = load_graph(file);
  EXPECT_EQ(node(defaults, "out").params.at("file").base_dir, file.parent_path());

  const GraphSpec typed = load_graph(file, {{}, {{"log", "run.csv"}}});
  EXPECT_EQ(node(typed, "out").params.at("file").value, "run.csv");
  EXPECT_EQ(node(typed, "out").params.at("file").base_dir, std::filesystem::current_path());
  EXPECT_EQ(node(typed, "also").params.at("file").value, "logs/run.csv");
  EXPECT_EQ(node(typed, "also").params.at("file").base_dir, file.parent_path());
}

// A value that is one variable and nothing else is the file's wiring: the loader says which.
TEST(GraphLoader, AValueThatIsOneVariableNamesIt) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({
    "variables": {"log": "default.csv", "folder": "logs", "count": 3},
    "nodes": {"src": {"type": "test.counter", "params": {"count": "${count}"}},
              "out": {"type": "test.record", "params": {"file": "${log}", "mode": "exact"}},
              "also": {"type": "test.record", "params": {"file": "${folder}/${log}"}}}
  })");
  const GraphSpec graph = load_graph(file, {{}, {{"log", "run.csv"}}});
  EXPECT_EQ(node(graph, "src").params.at("count").value, 3);
  EXPECT_EQ(node(graph, "src").params.at("count").variable, "count");
  EXPECT_EQ(node(graph, "out").params.at("file").variable, "log");
  EXPECT_EQ(node(graph, "out").params.at("mode").variable, std::nullopt);
  EXPECT_EQ(node(graph, "also").params.at("file").variable, std::nullopt);
}

TEST(GraphLoader, ReportsEveryProblemAtOnce) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({
    "nodez": {},
    "nodes": {"a": {"type": "test.counter", "params": {"count": "${missing}"}},
              "b": {"params": {"x": 1}},
              "c.d": {"type": "test.record"}},
    "edges": [["a.out"]],
    "runtime": {"when_full": "drop_newest"}
  })");
  const std::string f = file.string();
  EXPECT_EQ(
      load_error(file),
      f +
          ":/nodez: unknown key 'nodez' in graph file; did you mean 'nodes'? (expected one "
          "of 'description', 'plugins', 'variables', 'include', 'inputs', 'outputs', 'nodes', "
          "'edges', 'runtime')\n" +
          f + ":/nodes/a/params/count: unknown variable 'missing' (defined: none)\n" + f +
          ":/nodes/b: node 'b' has no \"type\" and overrides no included node; did you mean "
          "'a'?\n" +
          f + ":/nodes/c.d: node names must be non-empty, without '.', and not 'runtime'\n" + f +
          ":/edges/0: expected [\"node.port\", \"node.port\"] or {\"from\": ..., \"to\": "
          "...}\n" +
          f + ":/runtime/when_full: expected 'block' or 'drop_oldest', got \"drop_newest\"");
}

TEST(GraphLoader, UnknownOverrideTargetSuggestsNode) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({"nodes": {"camera": {"type": "test.counter"}}})");
  EXPECT_EQ(load_error(file, {{{"camera.count", "3"}, {"camra.count", "3"}, {"nodot", "1"}}, {}}),
            "command line:--set camra.count: no node named 'camra'; did you mean 'camera'?\n"
            "command line:--set nodot: expected NODE.PARAM=VALUE");
}

TEST(GraphLoader, IncludeCycleIsReported) {
  TempDir dir;
  dir.write("a.json", R"({"include": ["b.json"]})");
  dir.write("b.json", R"({"include": ["a.json"]})");
  const auto a = (dir.path() / "a.json").string();
  const auto b = (dir.path() / "b.json").string();
  EXPECT_EQ(load_error(dir.path() / "a.json"),
            b + ":/include/0/file: include cycle: " + a + " -> " + b + " -> " + a);
}

TEST(GraphLoader, ParseSettingNeedsEquals) {
  EXPECT_EQ(parse_setting("--set", "a.b=c=d").value, "c=d");
  for (const std::string text : {"a.b", "", "=c"}) {
    try {
      parse_setting("--set", text);
      ADD_FAILURE() << "'" << text << "' was taken as a setting";
    } catch (const Error& error) {
      EXPECT_EQ(std::string(error.what()), "--set: expected KEY=VALUE, got '" + text + "'");
    }
  }
}

// These aborted the process: nlohmann throws out_of_range, not parse_error, for a number
// that overflows a double.
TEST(GraphLoader, NumberBeyondDoubleRangeIsLocated) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({"nodes": {"src": {"type": "test.counter",
    "params": {"count": 1e400}}}})");
  EXPECT_EQ(load_error(file), file.string() +
                                  ":/nodes/src/params/count: expected a number within double "
                                  "range (magnitude below 1.8e308), got 1e400");

  const auto plain = dir.write("plain.json", R"({"nodes": {"src": {"type": "test.counter"}}})");
  GraphOverrides set;
  set.params = {{"src.count", "1e999"}};
  EXPECT_EQ(load_error(plain, set),
            "command line:--set src.count: expected a number within double range (magnitude "
            "below 1.8e308), got 1e999");
  GraphOverrides var;
  var.variables = {{"x", "-1e999"}};
  EXPECT_EQ(load_error(plain, var),
            "command line:--var x: expected a number within double range (magnitude below "
            "1.8e308), got -1e999");
  GraphOverrides twice;
  twice.params = {{"src.count", R"({"a": 1, "a": 2})"}};
  EXPECT_EQ(load_error(plain, twice),
            "command line:--set src.count: at /a: expected each key once in an object, got "
            "\"a\" again");
}

// 50 000 nested arrays overflowed the stack (SIGSEGV) in the recursive walks of the
// document; the reader stops at the 65th level.
TEST(GraphLoader, DeepNestingIsRefused) {
  TempDir dir;
  const auto file =
      dir.write("g.json", R"({"nodes": {"src": {"type": "test.counter", "params": {"count": )" +
                              std::string(50'000, '[') + std::string(50'000, ']') + "}}}}");
  std::string pointer = "/nodes/src/params/count";
  for (int level = 4; level < 64; ++level) pointer += "/0";
  EXPECT_EQ(load_error(file), file.string() + ":" + pointer +
                                  ": expected at most 64 nested arrays and objects, got more");
}

TEST(GraphLoader, DuplicateKeysAreRefused) {
  TempDir dir;
  // The second "src" silently replaced the first.
  const auto file = dir.write("g.json", R"({"nodes": {"src": {"type": "test.counter"},
    "src": {"type": "test.other"}}})");
  EXPECT_EQ(load_error(file), file.string() +
                                  ":/nodes/src: expected each key once in an object, got \"src\" "
                                  "again");
}

// An include of /dev/zero read forever; a FIFO would wait for a writer.
TEST(GraphLoader, IncludeOfADeviceIsRefused) {
  TempDir dir;
  const auto file = dir.write("g.json", R"({"include": ["/dev/zero"]})");
  EXPECT_EQ(load_error(file), file.string() +
                                  ":/include/0/file: is a character device; expected a regular "
                                  "file (graph file '/dev/zero')");
}

}  // namespace
}  // namespace tilth
