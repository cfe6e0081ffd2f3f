// A calibration file of a test's own, written to the temporary directory under the
// running test's name and removed at the end of the test.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace tilth::testing {

class CalibrationFile {
 public:
  explicit CalibrationFile(const nlohmann::json& document)
      : path_(std::filesystem::temp_directory_path() /
              ("tilth_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
               ".calib.json")) {
    std::ofstream(path_) << document.dump(2);
  }
  ~CalibrationFile() { std::filesystem::remove(path_); }
  CalibrationFile(const CalibrationFile&) = delete;
  CalibrationFile& operator=(const CalibrationFile&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace tilth::testing
