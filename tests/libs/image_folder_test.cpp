// libs/image_folder: the mask column of frames.csv rewritten in place (what `tilth
// recording import-masks` relies on to leave every other byte as it was), frames' file
// names, and image files read with errors that name them.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "image_folder/frames_csv.h"
#include "image_folder/image_file.h"
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

TEST(ReadImageFile, DecodesUnchangedAndNamesTheFileInErrors) {
  testing::TempDir dir;
  const cv::Mat gray(3, 4, CV_16UC1, cv::Scalar(1000));
  ASSERT_TRUE(cv::imwrite((dir.path() / "depth.png").string(), gray));
  const cv::Mat read = read_image_file(dir.path() / "depth.png");
  EXPECT_EQ(read.type(), CV_16UC1);
  EXPECT_EQ(cv::countNonZero(read != gray), 0);

  const auto missing = dir.path() / "missing.png";
  EXPECT_THROW(
      {
        try {
          read_image_file(missing);
        } catch (const Error& error) {
          EXPECT_EQ(std::string(error.what()), missing.string() + ": no such file");
          throw;
        }
      },
      Error);
  const auto text = dir.write("text.png", "not a PNG");
  EXPECT_THROW(
      {
        try {
          read_image_file(text);
        } catch (const Error& error) {
          EXPECT_EQ(std::string(error.what()), text.string() + ": not a readable image");
          throw;
        }
      },
      Error);
}

}  // namespace
}  // namespace tilth::recording
