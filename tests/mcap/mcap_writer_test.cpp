// McapWriter on its own: a live recording (store_when_behind) that closes chunks faster
// than they can be compressed stores the ones it cannot compress in time, uncompressed,
// and still writes every chunk in order with its messages intact; an offline one
// compresses every chunk.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "mcap_reader.h"
#include "mcap_writer.h"
#include "temp_dir.h"

namespace tilth::testing {
namespace {

namespace fs = std::filesystem;
constexpr int kChunks = 20;

// Noisy bytes, as camera images are: compressible, but not fast to compress.
std::string noisy_bytes(int seed) {
  cv::Mat noise(1024, 1024, CV_8UC1);
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 128, 4);
  return std::string(reinterpret_cast<const char*>(noise.data), noise.total());
}

// One 1 MiB message per chunk, closed at once.
std::vector<mcap::ChunkIndex> write_chunks(const fs::path& file, bool store_when_behind) {
  mcap::WriterOptions options;
  options.chunks_in_flight = 1;
  options.store_when_behind = store_when_behind;
  const std::string bytes = noisy_bytes(1);
  {
    mcap::McapWriter writer(file, options);
    const std::uint16_t channel = writer.add_channel(0, "/noise", "application/octet-stream");
    for (int i = 0; i < kChunks; ++i) {
      writer.write(channel, static_cast<std::uint32_t>(i), 1000 + i, 1000 + i, bytes);
      writer.close_chunk();
    }
    writer.finish();
  }
  mcap::McapReader reader(file);
  EXPECT_FALSE(reader.recovery());
  const std::vector<mcap::ChunkIndex> chunks = reader.chunks();
  EXPECT_EQ(chunks.size(), static_cast<std::size_t>(kChunks));
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const std::vector<mcap::Message> messages = reader.read_chunk(chunks[i]);  // CRC checked
    EXPECT_EQ(messages.size(), 1u);
    EXPECT_EQ(messages.at(0).sequence, i);  // in the order written
    EXPECT_EQ(messages.at(0).log_time, 1000 + i);
    EXPECT_TRUE(messages.at(0).data == bytes);
  }
  return chunks;
}

TEST(McapWriterTest, LiveRecordingStoresWhatItCannotCompressInTime) {
  TempDir dir;
  const auto chunks = write_chunks(dir.path() / "live.mcap", true);
  // The first chunk finds the compression thread free; the next ones are closed while
  // it is still busy (1 MiB of zstd takes milliseconds, closing a chunk microseconds).
  EXPECT_EQ(chunks.front().compression, "zstd");
  int stored = 0;
  for (const mcap::ChunkIndex& chunk : chunks) {
    EXPECT_TRUE(chunk.compression == "zstd" || chunk.compression.empty()) << chunk.compression;
    if (chunk.compression.empty()) {
      ++stored;
      EXPECT_EQ(chunk.compressed_size, chunk.uncompressed_size);
    } else {
      EXPECT_LT(chunk.compressed_size, chunk.uncompressed_size);
    }
  }
  EXPECT_GT(stored, 0);
}

TEST(McapWriterTest, OfflineRecordingCompressesEveryChunk) {
  TempDir dir;
  for (const mcap::ChunkIndex& chunk : write_chunks(dir.path() / "offline.mcap", false)) {
    EXPECT_EQ(chunk.compression, "zstd");
  }
}

}  // namespace
}  // namespace tilth::testing
