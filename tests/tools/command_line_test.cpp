// CommandLine: what every tool's arguments become (positional arguments in order, repeated
// options in order, flags), and the errors a mistyped command line gets.
#include "command_line.h"

#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tilth/error.h"

namespace tilth::cli {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

const std::set<std::string> kValued = {"--set", "--frames", "--out"};
const std::set<std::string> kFlags = {"--help", "--quiet"};

// argv as main() gets it: the program and its command first.
CommandLine parse(std::initializer_list<const char*> args,
                  const std::set<std::string>& flags = kFlags) {
  std::vector<std::string> text = {"tilth", "run"};
  text.insert(text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& arg : text) argv.push_back(arg.data());
  return CommandLine(static_cast<int>(argv.size()), argv.data(), 2, kValued, flags);
}

std::string error_of(std::initializer_list<const char*> args,
                     const std::set<std::string>& flags = kFlags) {
  try {
    parse(args, flags);
  } catch (const Error& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(CommandLine, KeepsPositionalArgumentsInTheirOrderAroundOptions) {
  const auto line = parse({"a.json", "--frames", "5", "b", "--quiet", "-", "c"});
  EXPECT_THAT(line.positional(), ElementsAre("a.json", "b", "-", "c"));
  EXPECT_EQ(line.value("--frames"), "5");
  EXPECT_TRUE(line.flag("--quiet"));
  EXPECT_FALSE(line.flag("--help"));
}

TEST(CommandLine, KeepsEveryValueOfARepeatedOptionInOrderAndTheLastAsItsValue) {
  const auto line = parse({"--set", "a.x=1", "--set=b.y=2", "--set", "c.z=3"});
  EXPECT_THAT(line.values("--set"), ElementsAre("a.x=1", "b.y=2", "c.z=3"));
  EXPECT_EQ(line.value("--set"), "c.z=3");
  EXPECT_TRUE(line.values("--out").empty());
  EXPECT_EQ(line.value("--out"), std::nullopt);
}

TEST(CommandLine, TakesWhateverFollowsAValuedOptionAsItsValue) {
  const auto line = parse({"--out", "-", "--set", "-x=1", "--frames", "--quiet", "--set", "--"});
  EXPECT_EQ(line.value("--out"), "-");
  EXPECT_THAT(line.values("--set"), ElementsAre("-x=1", "--"));
  EXPECT_EQ(line.value("--frames"), "--quiet");
  EXPECT_FALSE(line.flag("--quiet"));
  EXPECT_TRUE(line.positional().empty());
}

TEST(CommandLine, TakesAnEmptyValueAfterTheEqualsSign) {
  const auto line = parse({"--out=", "g.json", "--set", ""});
  EXPECT_THAT(line.values("--out"), ElementsAre(""));
  EXPECT_THAT(line.values("--set"), ElementsAre(""));
  EXPECT_THAT(line.positional(), ElementsAre("g.json"));
}

TEST(CommandLine, ReadsEveryArgumentAfterDoubleDashAsPositional) {
  const auto line = parse({"a", "--", "--help", "-h", "--frames", "-"});
  EXPECT_THAT(line.positional(), ElementsAre("a", "--help", "-h", "--frames", "-"));
  EXPECT_FALSE(line.flag("--help"));
  EXPECT_EQ(line.value("--frames"), std::nullopt);
  EXPECT_TRUE(parse({"--"}).positional().empty());
}

TEST(CommandLine, RefusesAValueGivenToAFlag) {
  EXPECT_EQ(error_of({"--quiet=no"}), "--quiet takes no value (see --help)");
  EXPECT_EQ(error_of({"--help="}), "--help takes no value (see --help)");
}

TEST(CommandLine, ReadsDashHAsHelpWhereTheCommandHasHelp) {
  EXPECT_TRUE(parse({"-h"}).flag("--help"));
  EXPECT_TRUE(parse({"--help"}).flag("--help"));
  EXPECT_EQ(error_of({"-h"}, {"--quiet"}), "unknown option -h (see --help)");
  EXPECT_EQ(error_of({"-hq"}), "unknown option -hq (see --help)");
  EXPECT_EQ(error_of({"-h=1"}), "unknown option -h=1 (see --help)");
  EXPECT_EQ(error_of({"-1"}), "unknown option -1 (see --help)");
}

TEST(CommandLine, NamesAnUnknownOptionAndTheNearestKnownOnes) {
  EXPECT_EQ(error_of({"--frame", "3"}),
            "unknown option --frame; did you mean '--frames'? (see --help)");
  EXPECT_EQ(error_of({"g.json", "--quite"}),
            "unknown option --quite; did you mean '--quiet'? (see --help)");
  EXPECT_EQ(error_of({"--sett=a.b=1"}),
            "unknown option --sett; did you mean '--set'? (see --help)");
  EXPECT_EQ(error_of({"--zzzzzz"}), "unknown option --zzzzzz (see --help)");
}

TEST(CommandLine, SaysWhichOptionLacksItsValue) {
  EXPECT_EQ(error_of({"g.json", "--frames"}), "--frames needs a value");
  EXPECT_EQ(error_of({"--out"}), "--out needs a value");
}

// The message count() or real() refuses `text` with, given as --frames.
std::string refusal(const char* text, bool whole) {
  const auto line = parse({"--frames", text});
  try {
    if (whole) {
      line.count("--frames", 1, 100);
    } else {
      line.real("--frames", 0, 10);
    }
  } catch (const Error& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(CommandLine, ReadsCountsWholeAndInTheirRange) {
  EXPECT_EQ(parse({"--frames", "12"}).count("--frames", 1, 100), 12u);
  EXPECT_EQ(parse({}).count("--frames", 1, 100), std::nullopt);
  for (const char* bad : {"5abc", "-1", " 5", "5.0", "", "0", "101"}) {
    EXPECT_EQ(refusal(bad, true),
              "--frames: expected a whole number in [1, 100], got '" + std::string(bad) + "'");
  }
}

TEST(CommandLine, ReadsRealsWholeAndInTheirRange) {
  EXPECT_DOUBLE_EQ(*parse({"--frames", "2.5"}).real("--frames", 0, 10), 2.5);
  for (const char* bad : {"2.5x", "nan", "11", "-0.1", ""}) {
    EXPECT_EQ(refusal(bad, false),
              "--frames: expected a number in [0, 10], got '" + std::string(bad) + "'");
  }
}

}  // namespace
}  // namespace tilth::cli
