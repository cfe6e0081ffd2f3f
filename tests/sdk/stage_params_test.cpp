// A stage's parameters made from its descriptor outside a graph file: defaults, overrides
// checked against the schema as the graph loader checks them.
#include "tilth/stage_params.h"

#include <gtest/gtest.h>

#include "tilth/error.h"

namespace tilth {
namespace {

StageDescriptor descriptor() {
  StageDescriptor d;
  d.type = "example.stage";
  d.params = {ParamSpec::number("height_mm", 3.0).range(0.5, 100),
              ParamSpec::choice("index", {"exg", "hue"}, "exg"), ParamSpec::integer("stride", 4)};
  return d;
}

std::string failure(const nlohmann::json& overrides) {
  try {
    stage_params(descriptor(), overrides);
  } catch (const Error& error) {
    return error.what();
  }
  return "made";
}

TEST(StageParams, EveryDeclaredParameterTakesItsDefaultUnlessSet) {
  const Params params = stage_params(descriptor(), {{"stride", 2}});
  EXPECT_EQ(params.number("height_mm"), 3.0);
  EXPECT_EQ(params.string("index"), "exg");
  EXPECT_EQ(params.integer("stride"), 2);
}

TEST(StageParams, AnUndeclaredParameterIsNamedWithTheStageType) {
  EXPECT_EQ(failure({{"heigth_mm", 5.0}}), "example.stage: no parameter 'heigth_mm'");
}

TEST(StageParams, AValueOutsideTheSchemaSaysWhatWasExpected) {
  const std::string message = failure({{"height_mm", 200.0}});
  EXPECT_EQ(message.rfind("example.stage: parameter 'height_mm': expected ", 0), 0u) << message;
  EXPECT_NE(message.find("got 200"), std::string::npos) << message;
  EXPECT_NE(failure({{"index", "ndvi"}}).find("got \"ndvi\""), std::string::npos);
}

}  // namespace
}  // namespace tilth
