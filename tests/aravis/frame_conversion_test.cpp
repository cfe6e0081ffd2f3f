// The conversions the camera stages make without a camera: which part of a buffer a ToF
// or colour stage takes (multi-part payloads with range, intensity and confidence parts,
// as a blaze-101 sends; the simulator has no 3D formats, so the buffers are built here),
// the cv::Mat over a part's pixels (row padding, size checks, no copy), the frame
// counters (16-bit block id wrap, incomplete, late and lost), and the message memory recycling.
#include <array>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "aravis/frame_counters.h"
#include "aravis/frame_layout.h"
#include "aravis/pixel_formats.h"
#include "aravis/recycling_allocator.h"
#include "tilth/error.h"

namespace tilth::aravis {
namespace {

constexpr ArvPixelFormat kConfidence16 = 0x011000C7u;  // GenICam Confidence16

// A part's pixels as a camera sends them: `rows` rows of `cols` 16-bit values, each row
// followed by `padding` bytes.
struct PartMemory {
  PartMemory(int cols, int rows, int padding, std::uint16_t first)
      : bytes(static_cast<std::size_t>(rows) * (static_cast<std::size_t>(cols) * 2 + padding),
              0xEE) {
    for (int y = 0; y < rows; ++y) {
      for (int x = 0; x < cols; ++x) {
        const std::uint16_t value = static_cast<std::uint16_t>(first + y * cols + x);
        std::memcpy(&bytes[static_cast<std::size_t>(y) * (cols * 2 + padding) + x * 2], &value, 2);
      }
    }
  }
  std::vector<std::uint8_t> bytes;
};

PartLayout part(std::uint32_t component, ArvBufferPartDataType type, ArvPixelFormat format,
                int cols, int rows, int padding, const PartMemory& memory) {
  PartLayout layout;
  layout.component_id = component;
  layout.data_type = type;
  layout.pixel_format = format;
  layout.width = cols;
  layout.height = rows;
  layout.x_padding = padding;
  layout.data = memory.bytes.data();
  layout.size = memory.bytes.size();
  return layout;
}

// Intensity (component 1), range (component 7, rows padded by 4 bytes) and confidence
// (component 9): the blaze-101's three components in one multi-part payload.
struct BlazePayload {
  PartMemory intensity{4, 3, 0, 1000};
  PartMemory range{4, 3, 4, 2000};
  PartMemory confidence{4, 3, 0, 3000};
  BufferLayout layout;

  BlazePayload() {
    layout.payload_type = ARV_BUFFER_PAYLOAD_TYPE_MULTIPART;
    layout.add(
        part(1, ARV_BUFFER_PART_DATA_TYPE_2D_IMAGE, ARV_PIXEL_FORMAT_MONO_16, 4, 3, 0, intensity));
    layout.add(
        part(7, ARV_BUFFER_PART_DATA_TYPE_3D_IMAGE, ARV_PIXEL_FORMAT_COORD3D_C_16, 4, 3, 4, range));
    layout.add(
        part(9, ARV_BUFFER_PART_DATA_TYPE_CONFIDENCE_MAP, kConfidence16, 4, 3, 0, confidence));
  }
};

cv::Mat wrap_tof(const PartLayout& chosen) {
  const ImageFormat* format = find_format(tof_formats(), chosen.pixel_format);
  EXPECT_NE(format, nullptr);
  return wrap_part(chosen, *format);
}

TEST(ToFPart, MultiPartPayloadGivesTheRangeComponentsPartWithoutCopying) {
  BlazePayload payload;
  const PartLayout& chosen = tof_part(payload.layout, 7u);
  EXPECT_EQ(chosen.component_id, 7u);
  const cv::Mat range = wrap_tof(chosen);
  ASSERT_EQ(range.type(), CV_16UC1);
  EXPECT_EQ(range.cols, 4);
  EXPECT_EQ(range.rows, 3);
  EXPECT_EQ(range.step[0], 4u * 2 + 4);  // the row padding is skipped, not copied
  EXPECT_EQ(range.data, payload.range.bytes.data());
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) EXPECT_EQ(range.at<std::uint16_t>(y, x), 2000 + y * 4 + x);
  }
}

TEST(ToFPart, WithoutAComponentIdTheOnlyPartInAToFFormatIsTaken) {
  BlazePayload payload;
  // Intensity is Mono16 too: take it out, leaving range as the only ToF-format part.
  BufferLayout layout;
  layout.payload_type = ARV_BUFFER_PAYLOAD_TYPE_MULTIPART;
  layout.add(payload.layout.parts()[1]);
  layout.add(payload.layout.parts()[2]);
  EXPECT_EQ(tof_part(layout, std::nullopt).component_id, 7u);
  EXPECT_EQ(tof_part(layout, 42u).component_id, 7u);  // an id no part has
}

TEST(ToFPart, AmbiguousOrMissingPartsAreErrorsThatDescribeTheParts) {
  BlazePayload payload;
  try {
    tof_part(payload.layout, std::nullopt);
    FAIL() << "two ToF-format parts and no component id";
  } catch (const Error& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("several parts in a ToF format"), std::string::npos) << what;
    EXPECT_NE(what.find("part 1: component 7, Coord3D_C16 (0x011000b8), 4x3"), std::string::npos)
        << what;
  }
  BufferLayout confidence_only;
  confidence_only.add(payload.layout.parts()[2]);
  confidence_only.add(payload.layout.parts()[2]);
  EXPECT_THROW(tof_part(confidence_only, 7u), Error);
}

TEST(ToFPart, ASinglePartImageIsTakenWhateverItsComponent) {
  PartMemory memory(6, 2, 0, 10);
  BufferLayout layout;
  layout.payload_type = ARV_BUFFER_PAYLOAD_TYPE_IMAGE;
  layout.add(
      part(0, ARV_BUFFER_PART_DATA_TYPE_2D_IMAGE, ARV_PIXEL_FORMAT_MONO_16, 6, 2, 0, memory));
  const cv::Mat gray = wrap_tof(tof_part(layout, 7u));
  EXPECT_EQ(gray.at<std::uint16_t>(1, 5), 21);
}

TEST(WrapPart, RejectsAPartTooSmallForItsSizeOrInAnotherFormat) {
  PartMemory memory(4, 3, 0, 0);
  PartLayout layout =
      part(0, ARV_BUFFER_PART_DATA_TYPE_2D_IMAGE, ARV_PIXEL_FORMAT_MONO_16, 4, 3, 0, memory);
  layout.size -= 1;
  EXPECT_THROW(wrap_tof(layout), Error);
  layout.size += 1;
  layout.x_padding = 2;  // 3 rows of 8 + 2 bytes no longer fit in 24
  EXPECT_THROW(wrap_tof(layout), Error);
  layout.x_padding = 0;
  EXPECT_THROW(wrap_part(layout, color_formats().front()), Error);  // Mono16 is not BayerRG8
}

TEST(ColorPart, EveryColourFormatKeepsItsPixelFormatAndLayout) {
  struct Expected {
    const char* name;
    PixelFormat format;
    int type;
  };
  const std::vector<Expected> expected = {
      {"BayerRG8", PixelFormat::kBayerRggb8, CV_8UC1},
      {"BayerGR8", PixelFormat::kBayerGrbg8, CV_8UC1},
      {"BayerGB8", PixelFormat::kBayerGbrg8, CV_8UC1},
      {"BayerBG8", PixelFormat::kBayerBggr8, CV_8UC1},
      {"RGB8", PixelFormat::kRgb8, CV_8UC3},
      {"BGR8", PixelFormat::kBgr8, CV_8UC3},
      {"Mono8", PixelFormat::kMono8, CV_8UC1},
  };
  ASSERT_EQ(color_formats().size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const ImageFormat& format = color_formats()[i];
    EXPECT_STREQ(format.genicam_name, expected[i].name);
    EXPECT_EQ(format.color, expected[i].format) << expected[i].name;
    EXPECT_EQ(format.cv_type, expected[i].type) << expected[i].name;
  }
  // An RGB8 image of 3x2 pixels, rows padded to 12 bytes.
  std::array<std::uint8_t, 24> memory{};
  for (std::size_t i = 0; i < memory.size(); ++i) memory[i] = static_cast<std::uint8_t>(i);
  PartLayout rgb;
  rgb.data_type = ARV_BUFFER_PART_DATA_TYPE_2D_IMAGE;
  rgb.pixel_format = ARV_PIXEL_FORMAT_RGB_8_PACKED;
  rgb.width = 3;
  rgb.height = 2;
  rgb.x_padding = 3;
  rgb.data = memory.data();
  rgb.size = memory.size();
  BufferLayout layout;
  layout.add(rgb);
  const cv::Mat pixels =
      wrap_part(color_part(layout), *find_format(color_formats(), rgb.pixel_format));
  EXPECT_EQ(pixels.at<cv::Vec3b>(1, 2), cv::Vec3b(18, 19, 20));
}

TEST(ColorPart, AMultiPartPayloadNeedsExactlyOneImagePart) {
  BlazePayload payload;
  EXPECT_EQ(color_part(payload.layout).component_id, 1u);  // the only 2D image part
  BufferLayout two_images;
  two_images.add(payload.layout.parts()[0]);
  two_images.add(payload.layout.parts()[0]);
  EXPECT_THROW(color_part(two_images), Error);
  BufferLayout no_image;
  no_image.add(payload.layout.parts()[1]);
  no_image.add(payload.layout.parts()[2]);
  EXPECT_THROW(color_part(no_image), Error);
}

TEST(FrameCounters, GapsInBlockIdsLessIncompleteFramesAreLostAcrossThe16BitWrap) {
  FrameCounters counters;
  counters.new_stream();
  for (std::uint64_t id : {65533u, 65534u, 1u, 2u}) counters.complete_arrived(id, 0);
  counters.complete_arrived(6, 0);  // 65535 (in the wrap), 3, 4 and 5 missing ...
  counters.incomplete_arrived();    // ... one given up as incomplete after 6 came whole
  CameraStatus status;
  counters.fill(status);
  EXPECT_EQ(status.incomplete, 1u);
  EXPECT_EQ(status.lost, 4u);  // the incomplete one may be any frame still to come
  counters.complete_arrived(7, 0);
  counters.fill(status);
  EXPECT_EQ(status.completed, 6u);
  EXPECT_EQ(status.lost, 3u);
  EXPECT_EQ(status.late, 0u);
}

TEST(FrameCounters, FramesMissingWhileTheStreamHadNoFreeBufferAreLateNotLost) {
  FrameCounters counters;
  counters.new_stream();
  counters.complete_arrived(10, 0);
  counters.complete_arrived(13, 376);  // 11 and 12 found no buffer (188 packets each)
  counters.complete_arrived(15, 376);  // 14 lost on the way
  // Frame 16 was taken late, after 17 had found no buffer: the underruns read then explain
  // the gap that 18 shows.
  counters.complete_arrived(16, 564);
  counters.complete_arrived(18, 564);
  CameraStatus status;
  counters.fill(status);
  EXPECT_EQ(status.lost, 1u);
  EXPECT_EQ(status.late, 3u);
  // A frame that got a buffer halfway comes out incomplete: it was neither late nor lost.
  counters.incomplete_arrived();
  counters.complete_arrived(19, 564);
  counters.fill(status);
  EXPECT_EQ(status.incomplete, 1u);
  EXPECT_EQ(status.lost + status.late, 3u);
}

TEST(FrameCounters, IncompleteFramesBeforeTheFirstCompleteOneHideNoLoss) {
  FrameCounters counters;
  counters.new_stream();
  counters.incomplete_arrived();  // the stream's first frames, before any whole one
  counters.incomplete_arrived();
  counters.complete_arrived(100, 0);
  counters.complete_arrived(103, 0);  // 101 and 102 never came
  CameraStatus status;
  counters.fill(status);
  EXPECT_EQ(status.incomplete, 2u);
  EXPECT_EQ(status.lost, 2u);
}

TEST(FrameCounters, ANewStreamStartsItsIdsAfreshAndKeepsTheTotals) {
  FrameCounters counters;
  counters.new_stream();
  counters.complete_arrived(500, 0);
  counters.complete_arrived(502, 0);
  counters.new_stream();  // the camera was reopened: its ids start again
  counters.complete_arrived(65000, 0);
  counters.complete_arrived(65001, 0);
  CameraStatus status;
  counters.fill(status);
  EXPECT_EQ(status.completed, 4u);
  EXPECT_EQ(status.lost, 1u);
  // An id more than half the 16-bit range ahead across the wrap is a restart, not a gap.
  counters.complete_arrived(40000, 0);
  counters.fill(status);
  EXPECT_EQ(status.lost, 1u);
}

struct Counted {
  explicit Counted(int& destroyed) : destroyed_(destroyed) {}
  ~Counted() { ++destroyed_; }
  int& destroyed_;
  std::array<char, 200> payload{};
};

TEST(RecyclingAllocator, AMessageDiesWithItsLastHolderAndItsMemoryIsUsedAgain) {
  auto blocks = std::make_shared<RecycledBlocks>();
  int destroyed = 0;
  auto first = std::allocate_shared<Counted>(RecyclingAllocator<Counted>(blocks), destroyed);
  const void* memory = first.get();
  auto holder = first;
  first.reset();
  EXPECT_EQ(destroyed, 0);
  holder.reset();
  EXPECT_EQ(destroyed, 1);  // at once, not when reused
  auto second = std::allocate_shared<Counted>(RecyclingAllocator<Counted>(blocks), destroyed);
  EXPECT_EQ(second.get(), memory);
  // The blocks outlive their owner's last reference while a message lives.
  blocks.reset();
  second.reset();
  EXPECT_EQ(destroyed, 2);
}

}  // namespace
}  // namespace tilth::aravis
