// libs/image_folder: the mask column of frames.csv rewritten in place (what `tilth
// recording import-masks` relies on to leave every other byte as it was), frames' file
// names, image files read with errors that name them, and recording.json's tags.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "image_folder/frames_csv.h"
#include "image_folder/image_file.h"
#include "image_folder/recording_json.h"
#include "source_tree.h"
#include "temp_dir.h"
#include "tilth/error.h"

namespace tilth::recording {
namespace {

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(RewriteMaskColumn, ReplacesOnlyTheNamedLinesMaskField) {
  testing::TempDir dir;
  // CRLF, an empty line, ground truth written as another writer writes it, the mask
  // column in the middle.
  const auto file =
      dir.write("frames.csv",
                "index,depth_timestamp_ns,color_timestamp_ns,depth,color,mask,ground_truth_mm\r\n"
                "0,10,11,depth/a.png,color/a.png,,518.0\r\n"
                "\r\n"
                "1,20,21,depth/b.png,color/b.png,old/b.png,\r\n"
                "2,30,31,depth/c.png,color/c.png,,518.123\r\n");
  const auto before = read_frames_csv(file);
  rewrite_mask_column(file, {{before[0].line, "mask/000000.png"}, {before[1].line, "mask/b.png"}});
  EXPECT_EQ(read_text(file),
            "index,depth_timestamp_ns,color_timestamp_ns,depth,color,mask,ground_truth_mm\r\n"
            "0,10,11,depth/a.png,color/a.png,mask/000000.png,518.0\r\n"
            "\r\n"
            "1,20,21,depth/b.png,color/b.png,mask/b.png,\r\n"
            "2,30,31,depth/c.png,color/c.png,,518.123\r\n");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "frames.csv.new"));
  const auto after = read_frames_csv(file);
  ASSERT_EQ(after.size(), 3u);
  EXPECT_EQ(after[0].mask, "mask/000000.png");
  EXPECT_EQ(after[2].mask, "");
}

TEST(RewriteMaskColumn, AddsTheColumnAtTheEndWhenThereIsNone) {
  testing::TempDir dir;
  const auto file = dir.write("frames.csv",
                              "color,index,depth_timestamp_ns,color_timestamp_ns,depth\n"
                              "color/a.png,0,10,11,depth/a.png\n"
                              "color/b.png,1,20,21,depth/b.png");  // no newline at the end
  rewrite_mask_column(file, {{3, "mask/000001.png"}});
  EXPECT_EQ(read_text(file),
            "color,index,depth_timestamp_ns,color_timestamp_ns,depth,mask\n"
            "color/a.png,0,10,11,depth/a.png,\n"
            "color/b.png,1,20,21,depth/b.png,mask/000001.png");
  EXPECT_EQ(read_frames_csv(file)[1].mask, "mask/000001.png");
}

TEST(FrameFileName, IsTheIndexInSixDigitsOrMore) {
  EXPECT_EQ(frame_file_name(12), "000012.png");
  EXPECT_EQ(frame_file_name(1234567), "1234567.png");
}

// recording.json with the shipped paper rig and `extra` fields.
std::filesystem::path recording_json_with(const testing::TempDir& dir, const std::string& extra) {
  dir.write("recording.json", R"({"format": "tilth-image-folder/1", "color_format": "bgr8",
                                  "calibration": ")" +
                                  testing::paper_rig_path().string() + "\"" + extra + "}");
  return dir.path();
}

// The message read() throws, or "no error".
template <typename Read>
std::string error_of(Read read) {
  try {
    read();
  } catch (const Error& error) {
    return error.what();
  }
  return "no error";
}

std::string recording_error_of(const std::filesystem::path& folder) {
  return error_of([&] { read_recording_json(folder); });
}

std::string image_error_of(const std::filesystem::path& file) {
  return error_of([&] { read_image_file(file); });
}

TEST(RecordingJson, ReadsTagsAsStrings) {
  testing::TempDir dir;
  const auto folder =
      recording_json_with(dir, R"(, "tags": {"site": "north field", "crop": "wheat"})");
  const RecordingJson recording = read_recording_json(folder);
  EXPECT_EQ(recording.tags,
            (std::map<std::string, std::string>{{"crop", "wheat"}, {"site", "north field"}}));
  EXPECT_TRUE(read_recording_json(recording_json_with(dir, "")).tags.empty());
}

TEST(RecordingJson, RefusesTagsThatAreNotStrings) {
  testing::TempDir dir;
  const std::string file = (dir.path() / "recording.json").string();
  EXPECT_EQ(recording_error_of(recording_json_with(dir, R"(, "tags": ["north"])")),
            file +
                ":/tags: expected an object of strings, e.g. {\"site\": \"north\"}, got "
                "[\"north\"]");
  EXPECT_EQ(recording_error_of(recording_json_with(dir, R"(, "tags": {"rows": 12})")),
            file + ":/tags/rows: expected a string, got 12");
}

TEST(ReadImageFile, DecodesUnchangedAndNamesTheFileInErrors) {
  testing::TempDir dir;
  const cv::Mat gray(3, 4, CV_16UC1, cv::Scalar(1000));
  ASSERT_TRUE(cv::imwrite((dir.path() / "depth.png").string(), gray));
  const cv::Mat read = read_image_file(dir.path() / "depth.png");
  EXPECT_EQ(read.type(), CV_16UC1);
  EXPECT_EQ(cv::countNonZero(read != gray), 0);

  const auto missing = dir.path() / "missing.png";
  EXPECT_EQ(image_error_of(missing), missing.string() + ": no such file");
  const auto too_long = dir.path() / (std::string(300, 'x') + ".png");
  EXPECT_EQ(image_error_of(too_long), too_long.string() + ": File name too long");
  const auto text = dir.write("text.png", "not a PNG");
  EXPECT_EQ(image_error_of(text), text.string() + ": not a readable image");
}

}  // namespace
}  // namespace tilth::recording
