// foxglove_msgs/msg/RawImage in CDR: images of every recorded encoding come back as they
// went in (a region of a larger image too), and a message that is not one Tilth can
// hold is refused with the field and what was expected.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "mcap/raw_image.h"
#include "tilth/error.h"

namespace tilth::testing {
namespace {

std::string error_of(const std::string& message) {
  try {
    mcap::decode_raw_image(message, "m");
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

TEST(RawImageTest, EveryEncodingComesBackAsItWentIn) {
  struct Case {
    const char* encoding;
    int type;
  };
  for (const Case& c : {Case{"mono16", CV_16UC1}, Case{"bgr8", CV_8UC3}, Case{"rgb8", CV_8UC3},
                        Case{"mono8", CV_8UC1}, Case{"bayer_gbrg8", CV_8UC1}}) {
    SCOPED_TRACE(c.encoding);
    cv::Mat whole(9, 13, c.type);
    cv::randu(whole, 0, 65536);
    const cv::Mat region = whole(cv::Rect(2, 1, 7, 5));  // not continuous
    const std::string message = mcap::encode_raw_image(region, c.encoding, 3'000'000'007, "tof");
    const mcap::RawImage image = mcap::decode_raw_image(message, "test");
    EXPECT_EQ(image.encoding, c.encoding);
    EXPECT_EQ(image.frame_id, "tof");
    EXPECT_EQ(image.timestamp_ns, 3'000'000'007);
    ASSERT_EQ(image.pixels.type(), c.type);
    ASSERT_EQ(image.pixels.size(), region.size());
    EXPECT_EQ(cv::norm(image.pixels, region, cv::NORM_INF), 0.0);
  }
}

TEST(RawImageTest, MalformedMessagesNameTheField) {
  const std::string good =
      mcap::encode_raw_image(cv::Mat(2, 3, CV_16UC1, cv::Scalar(7)), "mono16", 1, "tof");
  EXPECT_EQ(error_of("\x01\x01\x00\x00" + good.substr(4)),
            "m: expected a little-endian CDR message (header 00 01 00 00)");
  EXPECT_EQ(error_of(good.substr(0, good.size() - 1)),
            "m: data: 12 bytes at offset 48 run past the message's 59 bytes");
  std::string bad_encoding = good;
  bad_encoding.replace(bad_encoding.find("mono16"), 6, "yuv422");
  EXPECT_EQ(error_of(bad_encoding),
            "m: encoding: 'yuv422' is not recorded by Tilth; expected mono16, mono8, bgr8, rgb8 "
            "or bayer_*8");
  std::string bad_step = good;
  bad_step[40] = 4;  // step 4 < width 3 x 2 bytes
  EXPECT_EQ(error_of(bad_step),
            "m: expected 2 rows of step 4 >= width 3 x 2 bytes, got 12 data bytes");
}

TEST(RawImageTest, TimestampsMustFitARos2Time) {
  EXPECT_THROW(mcap::encode_raw_image(cv::Mat(1, 1, CV_8UC1), "mono8", -1, "tof"), Error);
  EXPECT_THROW(mcap::encode_raw_image(cv::Mat(1, 1, CV_8UC1), "mono8",
                                      (std::int64_t{1} << 31) * 1'000'000'000, "tof"),
               Error);
}

}  // namespace
}  // namespace tilth::testing
