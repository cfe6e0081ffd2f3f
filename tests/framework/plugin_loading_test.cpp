// Loading plugin libraries with Boost.DLL: the exact error for each way a plugin can be
// wrong, the search path, and that a loaded stage works.
#include <cstdlib>

#include <gtest/gtest.h>

#include "framework/install_layout.h"
#include "framework/stage_registry.h"
#include "tilth/abi.h"
#include "tilth/build_stamp.h"
#include "tilth/log.h"
#include "tilth/messages/raw_tof_frame.h"

namespace tilth {
namespace {

namespace fs = std::filesystem;

const fs::path kPlugins = TEST_PLUGIN_DIR;

fs::path plugin(const std::string& name) {
  return kPlugins / name / ("tilth_test_" + name + ".so");
}

std::string load_error(StageRegistry& registry, const fs::path& file) {
  try {
    registry.load(file);
  } catch (const Error& error) {
    return error.what();
  }
  return "loaded";
}

TEST(PluginLoading, LoadsAPluginAndMakesItsStages) {
  StageRegistry registry;
  registry.load(plugin("good"));
  EXPECT_EQ(registry.type_names(), (std::vector<std::string>{"testgood.pass", "testgood.throws"}));
  const auto* entry = registry.find("testgood.pass");
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(entry->plugin, "testgood");
  EXPECT_EQ(entry->file, plugin("good"));

  StageContext context{"p", Params(nlohmann::json{{"device", "cam0"}}), Logger("p"), {}};
  StageInstance instance = registry.create("testgood.pass", context);
  auto* transform = dynamic_cast<Transform*>(instance.stage.get());
  ASSERT_NE(transform, nullptr);
  RawTofFrame raw;
  raw.gray = cv::Mat(2, 3, CV_16UC1, cv::Scalar(7));
  const Packet in(FrameInfo{}, std::make_shared<const RawTofFrame>(raw));
  std::vector<Packet> outputs(1);
  Frame frame(FrameInfo{}, std::span<const Packet>(&in, 1), outputs);
  transform->process(frame);
  // The same image, shared, not copied.
  EXPECT_EQ(outputs[0].get<RawTofFrame>().gray.data, raw.gray.data);
}

TEST(PluginLoading, MissingFile) {
  StageRegistry registry;
  EXPECT_EQ(load_error(registry, kPlugins / "nowhere" / "tilth_x.so"),
            (kPlugins / "nowhere" / "tilth_x.so").string() + ": no such plugin library");
}

TEST(PluginLoading, ANameTheFileSystemRefusesIsMissingAndSaysWhy) {
  StageRegistry registry;
  const fs::path file = kPlugins / (std::string(300, 'x') + ".so");
  EXPECT_EQ(load_error(registry, file),
            file.string() + ": no such plugin library (File name too long)");
}

TEST(PluginLoading, NotATilthPlugin) {
  StageRegistry registry;
  EXPECT_EQ(load_error(registry, plugin("not_a_plugin")),
            plugin("not_a_plugin").string() +
                ": not a Tilth plugin (it does not export tilth_plugin_descriptor; use "
                "TILTH_PLUGIN)");
}

TEST(PluginLoading, AbiMismatch) {
  StageRegistry registry;
  EXPECT_EQ(load_error(registry, plugin("wrong_abi")),
            plugin("wrong_abi").string() + ": built for Tilth plugin ABI " +
                std::to_string(kAbiVersion + 1) + ", this runtime has ABI " +
                std::to_string(kAbiVersion) + "; rebuild the plugin against this SDK");
}

TEST(PluginLoading, RefusesAPluginBuiltOnOtherLibraries) {
  StageRegistry registry;
  const BuildStamp theirs{kThisBuild.compiler, kThisBuild.standard_library, "3.4", kThisBuild.json};
  EXPECT_EQ(load_error(registry, plugin("other_opencv")),
            plugin("other_opencv").string() + ": built with " + describe(theirs) +
                ", this runtime with " + describe(kThisBuild) +
                "; rebuild the plugin against this SDK and the same libraries (the plugin "
                "interface passes their types)");
  EXPECT_NE(describe(theirs).find("OpenCV 3.4"), std::string::npos);
  EXPECT_TRUE(registry.entries().empty());
}

TEST(PluginLoading, LoadsAPluginOfAnotherCompilerOnTheSameLibrariesWithAWarning) {
  std::vector<std::string> warnings;
  const LogHandler previous =
      set_log_handler([&](LogLevel level, std::string_view where, std::string_view message) {
        if (level == LogLevel::kWarning)
          warnings.push_back(std::string(where) + ": " + std::string(message));
      });
  StageRegistry registry;
  const std::string outcome = load_error(registry, plugin("other_compiler"));
  set_log_handler(previous);
  EXPECT_EQ(outcome, "loaded");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "plugins: " + plugin("other_compiler").string() +
                             ": built with Some Compiler 99, this runtime with " +
                             kThisBuild.compiler + "; loaded, as both use the same libraries");
}

TEST(PluginLoading, DuplicateStageType) {
  StageRegistry registry;
  registry.load(plugin("good"));
  EXPECT_EQ(load_error(registry, plugin("duplicate")),
            plugin("duplicate").string() + ": stage type 'testgood.pass' is already provided by " +
                plugin("good").string());
  EXPECT_EQ(registry.entries().size(), 2u);  // nothing of the refused plugin registered
}

TEST(PluginLoading, DescriptorThatContradictsItself) {
  StageRegistry registry;
  EXPECT_EQ(load_error(registry, plugin("bad_default")),
            plugin("bad_default").string() +
                ": stage type 'baddefault.pass': the default of parameter 'kernel' is 40, not an "
                "integer in [1, 31]");
}

TEST(PluginLoading, ThrowingConstructorNamesNodeAndType) {
  StageRegistry registry;
  registry.load(plugin("good"));
  StageContext context{"camera", Params(nlohmann::json{{"device", "cam7"}}), Logger("camera"), {}};
  try {
    registry.create("testgood.throws", context);
    FAIL() << "expected an error";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(),
                 "node 'camera' (testgood.throws) failed to start: device cam7 is not connected");
  }
}

TEST(PluginLoading, DirectoriesReportBrokenPluginsWithoutHidingOthers) {
  StageRegistry registry;
  const auto problems = registry.load_directories(
      {kPlugins / "not_a_plugin", kPlugins / "good", kPlugins / "wrong_abi", kPlugins / "good"});
  EXPECT_EQ(problems.size(), 2u);
  EXPECT_EQ(registry.type_names(), (std::vector<std::string>{"testgood.pass", "testgood.throws"}));
}

TEST(PluginLoading, SearchPathOrder) {
  setenv("TILTH_PLUGIN_PATH", "/opt/a:/opt/b", 1);
  const auto dirs = plugin_search_path("/graphs");
  unsetenv("TILTH_PLUGIN_PATH");
  ASSERT_EQ(dirs.size(), 4u);
  EXPECT_EQ(dirs[0], "/graphs");
  EXPECT_EQ(dirs[1], "/opt/a");
  EXPECT_EQ(dirs[2], "/opt/b");
  // The test runs from the build tree's bin/, laid out as an installed tree.
  EXPECT_EQ(dirs[3], TILTH_BUILD_PLUGIN_DIR);
  EXPECT_EQ(shipped_data_dir() / "graphs" / "demo.json",
            fs::path(TILTH_BUILD_DIR) / "share/tilth/graphs/demo.json");
  EXPECT_TRUE(fs::is_regular_file(shipped_data_dir() / "graphs" / "demo.json"));
  EXPECT_TRUE(is_plugin_file_name("tilth_sinks.so"));
  EXPECT_FALSE(is_plugin_file_name("libtilth_sdk.so"));
}

}  // namespace
}  // namespace tilth
