// Multi-part payloads through Aravis's own GigE Vision stream parser. The simulator sends
// no multi-part payloads (nor 3D formats), so the test opens it for a control connection
// and a stream only, and sends the stream a blaze-101-like frame itself: a leader listing
// three parts (intensity Mono16, range Coord3D_C16 with padded rows, confidence), one data
// packet per part, a trailer; GigE Vision 2 extended ids, as multi-part needs. The buffer
// Aravis fills from them goes through the ToF stage's conversion: the range part, wrapped
// without copying, the buffer back in the stream once the last cv::Mat lets go.
#include <arpa/inet.h>
#include <endian.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <optional>
#include <vector>

#include <arv.h>
#include <gtest/gtest.h>

#include "aravis/frame_layout.h"
#include "aravis/gobject_ptr.h"
#include "aravis/stream_buffers.h"
#include "fake_camera.h"
#include "tilth/error.h"

namespace tilth::aravis {
namespace {

constexpr ArvPixelFormat kConfidence16 = 0x011000C7u;

struct Part {
  std::uint16_t data_type;  // GigE Vision part data type: 1 2D image, 5 3D image, 9 confidence
  ArvPixelFormat pixel_format;
  std::uint16_t component;  // Aravis 0.8 reports a part's data purpose id as its component
  int width;
  int height;
  int x_padding;  // bytes after each row
  std::vector<std::uint8_t> bytes;
};

Part part16(std::uint16_t data_type, ArvPixelFormat format, std::uint16_t component, int width,
            int height, int x_padding, std::uint16_t first) {
  Part part{data_type, format, component, width, height, x_padding, {}};
  const int row_bytes = width * 2 + x_padding;
  part.bytes.assign(static_cast<std::size_t>(row_bytes * height), 0xEE);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const auto value = static_cast<std::uint16_t>(first + y * width + x);
      std::memcpy(&part.bytes[static_cast<std::size_t>(y * row_bytes + x * 2)], &value, 2);
    }
  }
  return part;
}

// Sends GVSP packets to a stream, from the camera's address (Aravis filters on it).
class GvspSender {
 public:
  GvspSender(const std::string& from, const std::string& to, std::uint16_t port)
      : socket_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    sockaddr_in source{};
    source.sin_family = AF_INET;
    inet_pton(AF_INET, from.c_str(), &source.sin_addr);
    EXPECT_EQ(::bind(socket_, reinterpret_cast<sockaddr*>(&source), sizeof source), 0);
    destination_.sin_family = AF_INET;
    destination_.sin_port = htons(port);
    inet_pton(AF_INET, to.c_str(), &destination_.sin_addr);
  }
  ~GvspSender() { ::close(socket_); }

  // One block: leader, one data packet per part (each at its offset in the payload), trailer.
  void send_multipart(std::uint64_t block_id, std::uint64_t timestamp,
                      const std::vector<Part>& parts) {
    std::vector<std::uint8_t> leader =
        header(kLeader, static_cast<std::uint32_t>(parts.size()), block_id, 0);
    append16(leader, 0);       // flags
    append16(leader, 0x000A);  // payload type: multi-part
    append32(leader, static_cast<std::uint32_t>(timestamp >> 32));
    append32(leader, static_cast<std::uint32_t>(timestamp));
    for (const auto& part : parts) {  // 48 bytes each
      append16(leader, part.data_type);
      append16(leader, 0);  // part length, high
      append32(leader, static_cast<std::uint32_t>(part.bytes.size()));
      append32(leader, part.pixel_format);
      append16(leader, 0);               // reserved
      leader.push_back(0);               // source id
      leader.push_back(0);               // additional zones
      append32(leader, 0);               // zone directions
      append16(leader, part.component);  // data purpose id
      append16(leader, 0);               // region id
      append32(leader, static_cast<std::uint32_t>(part.width));
      append32(leader, static_cast<std::uint32_t>(part.height));
      append32(leader, 0);  // x offset
      append32(leader, 0);  // y offset
      append16(leader, static_cast<std::uint16_t>(part.x_padding));
      append16(leader, 0);  // y padding
      append32(leader, 0);  // reserved
    }
    send(leader);
    std::uint32_t packet_id = 1;
    std::uint32_t offset = 0;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      std::vector<std::uint8_t> data = header(kMultipartData, 0, block_id, packet_id++);
      data.push_back(static_cast<std::uint8_t>(i));  // part id
      data.push_back(0);                             // zone
      append16(data, 0);                             // offset, high
      append32(data, offset);                        // offset in the payload
      data.insert(data.end(), parts[i].bytes.begin(), parts[i].bytes.end());
      send(data);
      offset += static_cast<std::uint32_t>(parts[i].bytes.size());
    }
    std::vector<std::uint8_t> trailer = header(kTrailer, 0, block_id, packet_id);
    append32(trailer, 0x000A);
    append32(trailer, 0);
    send(trailer);
  }

 private:
  static constexpr std::uint8_t kLeader = 0x01;
  static constexpr std::uint8_t kTrailer = 0x02;
  static constexpr std::uint8_t kMultipartData = 0x07;

  static void append16(std::vector<std::uint8_t>& out, std::uint16_t value) {
    out.push_back(static_cast<std::uint8_t>(value >> 8));
    out.push_back(static_cast<std::uint8_t>(value));
  }
  static void append32(std::vector<std::uint8_t>& out, std::uint32_t value) {
    append16(out, static_cast<std::uint16_t>(value >> 16));
    append16(out, static_cast<std::uint16_t>(value));
  }
  // Status, then the extended header: flags, extended-id flag with the packet format and
  // (in a leader) the part count, the 64-bit block id, the 32-bit packet id.
  static std::vector<std::uint8_t> header(std::uint8_t format, std::uint32_t low,
                                          std::uint64_t block_id, std::uint32_t packet_id) {
    std::vector<std::uint8_t> out;
    append16(out, 0);  // status: success
    append16(out, 0);  // flags
    append32(out, 0x80000000u | (static_cast<std::uint32_t>(format) << 24) | low);
    append32(out, static_cast<std::uint32_t>(block_id >> 32));
    append32(out, static_cast<std::uint32_t>(block_id));
    append32(out, packet_id);
    return out;
  }
  void send(const std::vector<std::uint8_t>& packet) {
    ASSERT_EQ(::sendto(socket_, packet.data(), packet.size(), 0,
                       reinterpret_cast<const sockaddr*>(&destination_), sizeof destination_),
              static_cast<ssize_t>(packet.size()));
  }

  int socket_;
  sockaddr_in destination_{};
};

gint input_buffers(ArvStream* stream) {
  gint input = 0;
  gint output = 0;
  arv_stream_get_n_buffers(stream, &input, &output);
  return input;
}

// A stream on the simulator's control connection, and a sender of GVSP packets to it.
class MultiPartStream : public ::testing::Test {
 protected:
  void SetUp() override {
    fake_.start();
    GErrorSlot error;
    camera_.reset(arv_camera_new(fake_.address().c_str(), error.out()));
    error.check("opening the simulator");
    arv_camera_gv_set_stream_options(camera_.get(), ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    stream_.reset(arv_camera_create_stream(camera_.get(), nullptr, nullptr, error.out()));
    error.check("creating the stream");
    buffers_ = StreamBuffers::create(stream_.get(), 2, 4096);
    ASSERT_EQ(input_buffers(stream_.get()), 2);

    // The address the stream listens on (Aravis keeps ownership).
    GSocketAddress* host =
        arv_gv_device_get_interface_address(ARV_GV_DEVICE(arv_camera_get_device(camera_.get())));
    gchar* host_address =
        g_inet_address_to_string(g_inet_socket_address_get_address(G_INET_SOCKET_ADDRESS(host)));
    sender_.emplace(fake_.address(), host_address,
                    arv_gv_stream_get_port(ARV_GV_STREAM(stream_.get())));
    g_free(host_address);
  }

  // A blaze-101-like frame: intensity (component 1), range with padded rows (component
  // 7), confidence (component 9), each part 8x4 pixels.
  PoppedBuffer receive_blaze_frame(std::uint64_t block_id) {
    sender_->send_multipart(block_id, 123456789, parts_);
    return PoppedBuffer(buffers_, arv_stream_timeout_pop_buffer(stream_.get(), 1'000'000));
  }

  const std::vector<Part> parts_ = {
      part16(1, ARV_PIXEL_FORMAT_MONO_16, 1, 8, 4, 0, 1000),
      part16(5, ARV_PIXEL_FORMAT_COORD3D_C_16, 7, 8, 4, 6, 2000),  // rows padded by 6 bytes
      part16(9, kConfidence16, 9, 8, 4, 0, 3000),
  };
  testing::FakeCamera fake_{"127.0.0.18", "TILTH18"};
  GObjectPtr<ArvCamera> camera_;
  GObjectPtr<ArvStream> stream_;
  std::shared_ptr<StreamBuffers> buffers_;
  std::optional<GvspSender> sender_;
};

void expect_values(const cv::Mat& gray, int first) {
  ASSERT_EQ(gray.cols, 8);
  ASSERT_EQ(gray.rows, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) EXPECT_EQ(gray.at<std::uint16_t>(y, x), first + y * 8 + x);
  }
}

TEST_F(MultiPartStream, TheRangePartOfAMultiPartFrameFromAravisIsWrappedWithoutCopying) {
  PoppedBuffer popped = receive_blaze_frame(42);
  ASSERT_TRUE(popped) << "Aravis made no buffer of the packets";
  ASSERT_EQ(arv_buffer_get_status(popped.get()), ARV_BUFFER_STATUS_SUCCESS);
  EXPECT_EQ(arv_buffer_get_frame_id(popped.get()), 42u);
  const BufferLayout layout = layout_of(popped.get());
  EXPECT_EQ(layout.payload_type, ARV_BUFFER_PAYLOAD_TYPE_MULTIPART);
  ASSERT_EQ(layout.parts().size(), 3u);
  EXPECT_EQ(layout.parts()[0].component_id, 1u);
  EXPECT_EQ(layout.parts()[1].data_type, ARV_BUFFER_PART_DATA_TYPE_3D_IMAGE);
  EXPECT_EQ(layout.parts()[2].pixel_format, kConfidence16);

  const PartLayout& range = tof_part(layout, 7u);
  cv::Mat gray = wrap_part(range, *find_format(tof_formats(), range.pixel_format));
  popped.lend_to(gray);
  EXPECT_EQ(gray.step[0], 8u * 2 + 6);
  expect_values(gray, 2000);
  // The pixels are the buffer's own: the intensity part first, then the range part.
  EXPECT_EQ(gray.data, gray.u->data + parts_[0].bytes.size());

  cv::Mat copy = gray;
  gray.release();
  EXPECT_EQ(input_buffers(stream_.get()), 1);  // the copy still holds the buffer
  copy.release();
  EXPECT_EQ(input_buffers(stream_.get()), 2);  // back in the stream
}

// What aravis.tof_camera does with intensity_component: both parts of one capture, each
// wrapped without copying, the buffer back in the stream once neither is held.
TEST_F(MultiPartStream, TheIntensityAndRangeOfOneCaptureShareItsBufferUntilBothAreReleased) {
  PoppedBuffer popped = receive_blaze_frame(43);
  ASSERT_TRUE(popped) << "Aravis made no buffer of the packets";
  const BufferLayout layout = layout_of(popped.get());
  const ImageFormat& mono16 = *find_format(tof_formats(), ARV_PIXEL_FORMAT_MONO_16);
  cv::Mat range =
      wrap_part(tof_part(layout, 7u), *find_format(tof_formats(), ARV_PIXEL_FORMAT_COORD3D_C_16));
  cv::Mat intensity = wrap_part(component_part(layout, 1u), mono16);
  cv::Mat* const both[] = {&range, &intensity};
  popped.lend_to(both);
  expect_values(range, 2000);
  expect_values(intensity, 1000);
  EXPECT_EQ(intensity.data, intensity.u->data);  // the first part, at the buffer's start
  EXPECT_EQ(range.u, intensity.u);

  range.release();
  EXPECT_EQ(input_buffers(stream_.get()), 1);  // the intensity still holds the buffer
  cv::Mat kept = intensity;
  intensity.release();
  EXPECT_EQ(input_buffers(stream_.get()), 1);
  kept.release();
  EXPECT_EQ(input_buffers(stream_.get()), 2);  // back in the stream

  EXPECT_THROW(component_part(layout, 4u), Error);  // no such component in the frame
  try {
    component_part(layout, 4u);
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "no part of the frame belongs to component 4 (part 0: component 1, " +
                  describe_pixel_format(ARV_PIXEL_FORMAT_MONO_16) + ", 8x4; part 1: component 7, " +
                  describe_pixel_format(ARV_PIXEL_FORMAT_COORD3D_C_16) +
                  ", 8x4; part 2: component 9, 0x011000c7, 8x4)");
  }
}

}  // namespace
}  // namespace tilth::aravis
