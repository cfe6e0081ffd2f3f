// Every JSON text Tilth reads: what is refused, and where the error says it is.
#include "tilth/json_input.h"

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "temp_dir.h"

namespace tilth {
namespace {

std::string parse_failure(const std::string& text, JsonSyntax syntax = {}) {
  try {
    parse_json(text, "t.json", syntax);
  } catch (const JsonError& error) {
    return error.what();
  }
  return "parsed";
}

std::string read_failure(const std::filesystem::path& file) {
  try {
    read_json_text(file, "test file");
  } catch (const JsonError& error) {
    return error.what();
  }
  return "read";
}

std::string nested_arrays(std::size_t depth) {
  return std::string(depth, '[') + std::string(depth, ']');
}

TEST(JsonInput, DuplicateKeyIsRefusedAtItsPointer) {
  EXPECT_EQ(parse_failure(R"({"a": {"b": [1, {"fx": 497, "fx": 518}]}})"),
            "t.json:/a/b/1/fx: expected each key once in an object, got \"fx\" again");
  // The same key in two objects is no duplicate; nor in an object after its sibling.
  EXPECT_EQ(parse_json(R"({"a": {"x": 1}, "b": {"x": 2}, "c": [{"x": 3}, {"x": 4}]})", "t.json")
                .at("c")
                .at(1)
                .at("x"),
            4);
}

TEST(JsonInput, DuplicateKeyInOrderedJsonAndEscapedPointer) {
  try {
    (void)parse_ordered_json(R"({"z": 1, "a/b~": {"k": 1, "k": 2}})", "t.json");
    FAIL() << "parsed";
  } catch (const JsonError& error) {
    EXPECT_EQ(error.pointer(), "/a~1b~0/k");
    EXPECT_FALSE(error.malformed());
  }
}

// 50 000 nested arrays overflowed the stack of the code walking the document; the parser
// stops at the 65th, before it has built anything deep.
TEST(JsonInput, DeepNestingIsRefusedBeforeTheStackOverflows) {
  std::string pointer;
  for (std::size_t i = 0; i < kMaxJsonDepth; ++i) pointer += "/0";
  EXPECT_EQ(parse_failure(nested_arrays(50'000)),
            "t.json:" + pointer + ": expected at most 64 nested arrays and objects, got more");
  EXPECT_EQ(parse_json(nested_arrays(kMaxJsonDepth), "t.json").dump(), nested_arrays(64));
  EXPECT_NE(parse_failure(nested_arrays(kMaxJsonDepth + 1)), "parsed");
  std::string below_b = "/b";
  for (std::size_t i = 1; i < kMaxJsonDepth; ++i) below_b += "/0";
  EXPECT_EQ(parse_failure(R"({"a": 1, "b": )" + nested_arrays(100) + "}"),
            "t.json:" + below_b + ": expected at most 64 nested arrays and objects, got more");
}

TEST(JsonInput, NumberBeyondDoubleRangeIsLocated) {
  EXPECT_EQ(parse_failure(R"({"x": [1, 1e400]})"),
            "t.json:/x/1: expected a number within double range (magnitude below 1.8e308), got "
            "1e400");
  EXPECT_EQ(parse_failure("-1e999"),
            "t.json: expected a number within double range (magnitude below 1.8e308), got -1e999");
  EXPECT_EQ(parse_json("1.7e308", "t.json"), 1.7e308);
}

TEST(JsonInput, MalformedJsonGivesLineAndColumn) {
  try {
    (void)parse_json("{\n  \"a\": [1,,2]\n}", "t.json");
    FAIL() << "parsed";
  } catch (const JsonError& error) {
    EXPECT_TRUE(error.malformed());
    EXPECT_EQ(error.line(), 2);
    EXPECT_EQ(error.column(), 11);
    EXPECT_EQ(std::string(error.what()).rfind("t.json:2:11: malformed JSON: syntax error", 0), 0u)
        << error.what();
  }
}

TEST(JsonInput, CommentsOnlyWhereAllowed) {
  const std::string text = "{\"a\": 1 // one\n}";
  EXPECT_EQ(parse_json(text, "t.json", {.comments = true}).at("a"), 1);
  EXPECT_NE(parse_failure(text), "parsed");
}

TEST(JsonInput, OnlySmallRegularFilesAreRead) {
  testing::TempDir dir;
  const auto file = dir.write("g.json", "{}");
  EXPECT_EQ(read_json_text(file, "test file"), "{}");

  EXPECT_EQ(read_failure("/dev/zero"),
            "/dev/zero: is a character device; expected a regular file (test file)");
  EXPECT_EQ(read_failure(dir.path()),
            dir.path().string() + ": is a folder; expected a regular file (test file)");
  // Opening a FIFO for reading would wait for a writer forever.
  const auto fifo = dir.path() / "fifo.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(read_failure(fifo), fifo.string() + ": is a FIFO; expected a regular file (test file)");
  EXPECT_EQ(read_failure(dir.path() / "none.json"),
            (dir.path() / "none.json").string() + ": cannot read test file");

  // Sparse: 17 MiB long, no disk used.
  const auto large = dir.write("large.json", "");
  std::filesystem::resize_file(large, kMaxJsonFileBytes + 1);
  EXPECT_EQ(read_failure(large), large.string() + ": is " + std::to_string(kMaxJsonFileBytes + 1) +
                                     " bytes; expected at most " +
                                     std::to_string(kMaxJsonFileBytes) + " for a test file");
  std::filesystem::resize_file(large, kMaxJsonFileBytes);
  EXPECT_EQ(read_json_text(large, "test file").size(), kMaxJsonFileBytes);
}

}  // namespace
}  // namespace tilth
