#include "command_usage.h"

#include <gtest/gtest.h>

namespace tilth::cli {
namespace {

constexpr const char* kUsage = R"(usage: tilth recording COMMAND ARGS

  info FILE                 an MCAP recording's channels
                            and metadata
  import DIR FILE           an image-folder recording to an MCAP recording
        [--compression zstd|lz4|none] [--overwrite]
  import-masks DIR LABELS   masks drawn in a labelling tool

  solve DIR...
      Both cameras' intrinsics.
        --report FILE   the report

Exit code 0 on success.
)";

TEST(CommandUsage, TheCommandsLinesUnderTheToolsName) {
  EXPECT_EQ(command_usage(kUsage, "info"),
            "usage: tilth recording\n\n"
            "  info FILE                 an MCAP recording's channels\n"
            "                            and metadata\n");
  EXPECT_EQ(command_usage(kUsage, "solve"),
            "usage: tilth recording\n\n"
            "  solve DIR...\n"
            "      Both cameras' intrinsics.\n"
            "        --report FILE   the report\n");
}

TEST(CommandUsage, ACommandIsAWholeWord) {
  EXPECT_EQ(command_usage(kUsage, "import"),
            "usage: tilth recording\n\n"
            "  import DIR FILE           an image-folder recording to an MCAP recording\n"
            "        [--compression zstd|lz4|none] [--overwrite]\n");
  EXPECT_EQ(command_usage(kUsage, "import-masks"),
            "usage: tilth recording\n\n"
            "  import-masks DIR LABELS   masks drawn in a labelling tool\n");
  EXPECT_EQ(command_usage(kUsage, "imp"), std::nullopt);
}

TEST(CommandUsage, NoneForWhatIsNotACommand) {
  EXPECT_EQ(command_usage(kUsage, "repair"), std::nullopt);
  EXPECT_EQ(command_usage(kUsage, "FILE"), std::nullopt);
  EXPECT_EQ(command_usage(kUsage, "Exit"), std::nullopt);  // not indented
  EXPECT_EQ(command_usage("", "info"), std::nullopt);
}

}  // namespace
}  // namespace tilth::cli
