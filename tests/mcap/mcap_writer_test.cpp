// McapWriter on its own: a live recording (store_when_behind) that closes chunks faster
// than they can be compressed stores the ones it cannot compress in time, uncompressed,
// and still writes every chunk in order with its messages intact; an offline one
// compresses every chunk; a full disk ends it with an error, never an abort.
#include <signal.h>
#include <sys/resource.h>

#include <cstdio>
#include <regex>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "mcap/mcap_reader.h"
#include "mcap/mcap_recording.h"
#include "mcap/mcap_writer.h"
#include "temp_dir.h"
#include "tilth/error.h"

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

// Writes 1 MiB chunks into a file limited to 5 MiB until a write fails, then checks the
// error against the file: 0 when they agree. For a child process: the limit is process-wide.
int write_until_the_disk_is_full() {
  const TempDir dir;
  const fs::path file = dir.path() / "full.mcap";
  ::signal(SIGXFSZ, SIG_IGN);
  constexpr rlim_t kLimit = 5 * 1024 * 1024;
  const rlimit limit{kLimit, kLimit};
  ::setrlimit(RLIMIT_FSIZE, &limit);
  std::string failure;
  {
    mcap::WriterOptions options;
    options.chunks_in_flight = 2;
    mcap::McapWriter writer(file, options);
    const std::uint16_t channel = writer.add_channel(0, "/noise", "application/octet-stream");
    try {
      for (int i = 0; i < 40; ++i) {
        writer.write(channel, static_cast<std::uint32_t>(i), i, i, noisy_bytes(i));
        writer.close_chunk();
      }
      writer.finish();
    } catch (const Error& error) {
      failure = error.what();
    }
    try {
      writer.finish();
      failure = "finish() after the failure did not throw";
    } catch (const Error& error) {
      if (error.what() != failure) failure += "; then: " + std::string(error.what());
    }
  }  // the destructor waits for the chunks still being compressed
  std::fprintf(stderr, "%s\n", failure.c_str());
  std::smatch kept;
  const std::regex pattern("the file keeps its first ([0-9]+) bytes \\(([0-9]+) messages\\)");
  if (!std::regex_search(failure, kept, pattern)) return 1;
  const mcap::RecordingInfo info = mcap::recording_info(file);
  const bool consistent = std::stoull(kept[1]) == fs::file_size(file) &&
                          std::stoull(kept[2]) == info.message_count && info.message_count >= 3 &&
                          !info.has_summary && info.readable_bytes == fs::file_size(file);
  return consistent ? 0 : 2;
}

// A full disk (a file size limit, with SIGXFSZ ignored: writes fail with EFBIG as with
// ENOSPC) while zstd chunks are compressed on their threads: the writer throws an error
// naming the file, the offset and the cause, throws it again on every later call, cuts
// the file back to its last complete chunk (readable, without a summary), and is
// destroyed without aborting.
TEST(McapWriterTest, FullDiskEndsTheWriterWithAnErrorNotAnAbort) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(std::_Exit(write_until_the_disk_is_full()), ::testing::ExitedWithCode(0),
              "/full\\.mcap: cannot write (at|before) offset [0-9]+: File too large; writing "
              "stopped, the file keeps its first [0-9]+ bytes \\([0-9]+ messages\\) without a "
              "summary");
}

}  // namespace
}  // namespace tilth::testing
