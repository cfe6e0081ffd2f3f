// What the MCAP tests share: the recording tests' fixture with the mcap plugin loaded
// too, graphs feeding chosen frames into mcap.writer and replaying a file through
// mcap.player, and the frame checks.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "recording_fixture.h"

namespace tilth::testing {

class McapTest : public RecordingTest {
 protected:
  McapTest();

  // test.feed (frames_ in `format`, each with its truth) -> mcap.writer at `file`.
  RunResult record(const fs::path& file, PixelFormat format, nlohmann::json writer_params = {});
  // mcap.player -> test.capture.
  static std::string player_graph(const fs::path& file, nlohmann::json player_params = {});
  // Runs player_graph(); captured_ holds what it played.
  RunResult play(const fs::path& file, nlohmann::json player_params = {});
  // captured_ holds exactly frames_[first, first + count) as recorded, host times too
  // (played with host_time: recorded).
  void expect_played(PixelFormat format, std::size_t first, std::size_t count);

  const fs::path calibration_file_ = dir_.path() / "small.calib.json";
  std::vector<TestFrame> frames_;
  // Where record() says each colour image lies on the sensor (frames_ then hold a window).
  std::optional<cv::Point> color_sensor_offset_;
};

}  // namespace tilth::testing
