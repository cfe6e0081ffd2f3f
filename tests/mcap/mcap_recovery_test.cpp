// A recording cut off mid-write (power loss, kill -9) plays up to its last complete
// chunk with a warning saying how much was recovered, and `repair` rewrites it with a
// summary; a chunk whose CRC does not match is reported with its file offset. Damage
// elsewhere: a forged size costs no memory and is a located error; a damaged summary
// is read around by scanning; `repair` salvages every intact chunk around a damaged one
// into a new file and says what it dropped; `info` checks every CRC.
#include <sys/resource.h>

#include <cstring>
#include <fstream>

#include "mcap/mcap_reader.h"
#include "mcap/mcap_recording.h"
#include "mcap/mcap_writer.h"
#include "mcap_fixture.h"
#include "tilth/error.h"

namespace tilth::testing {
namespace {

using nlohmann::json;

void copy_prefix(const fs::path& from, const fs::path& to, std::uint64_t size) {
  std::string bytes = read_text(from);
  ASSERT_LE(size, bytes.size());
  std::ofstream(to, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(size));
}

// Writes `bytes` over the file's bytes at `offset`.
void patch(const fs::path& file, std::uint64_t offset, std::string_view bytes) {
  std::fstream out(file, std::ios::in | std::ios::out | std::ios::binary);
  out.seekp(static_cast<std::streamoff>(offset));
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good());
}

std::string u64_bytes(std::uint64_t value) {
  std::string bytes(8, '\0');
  std::memcpy(bytes.data(), &value, 8);
  return bytes;
}

void flip_bit(const fs::path& file, std::uint64_t offset) {
  const std::string bytes = read_text(file);
  patch(file, offset, std::string(1, static_cast<char>(bytes.at(offset) ^ 0x01)));
}

// The peak resident memory of this process so far.
std::uint64_t peak_rss_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;
}

class McapRecoveryTest : public McapTest {
 protected:
  // Six frames, one chunk each (chunk_size 1).
  void SetUp() override {
    frames_ = make_frames(6, small_calibration(), 3);
    const RunResult recorded = record(complete_, PixelFormat::kBgr8, {{"chunk_size", 1}});
    ASSERT_FALSE(recorded.failed) << recorded.failure;
    chunks_ = mcap::McapReader(complete_).chunks();
    ASSERT_EQ(chunks_.size(), frames_.size());
  }

  bool warned(const std::string& text) const {
    for (const std::string& warning : warnings()) {
      if (warning.find(text) != std::string::npos) return true;
    }
    return false;
  }

  const fs::path complete_ = dir_.path() / "complete.mcap";
  std::vector<mcap::ChunkIndex> chunks_;
};

TEST_F(McapRecoveryTest, CutFilePlaysItsCompleteChunksAndRepairs) {
  struct Cut {
    std::uint64_t size;
    std::size_t complete_chunks;
  };
  std::vector<Cut> cuts;
  for (std::size_t k = 0; k < chunks_.size(); ++k) {
    const mcap::ChunkIndex& chunk = chunks_[k];
    cuts.push_back({chunk.chunk_start_offset + 5, k});                           // in its prefix
    cuts.push_back({chunk.chunk_start_offset + chunk.chunk_length / 2, k});      // mid-chunk
    cuts.push_back({chunk.chunk_start_offset + chunk.chunk_length - 1, k});      // its last byte
    cuts.push_back({chunk.chunk_start_offset + chunk.chunk_length + 3, k + 1});  // in its index
  }
  cuts.push_back({fs::file_size(complete_) - 30, chunks_.size()});  // in the summary

  for (const Cut& cut : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(cut.size) + " bytes");
    const fs::path cut_file = dir_.path() / "cut.mcap";
    copy_prefix(complete_, cut_file, cut.size);

    const RunResult played = play(cut_file, {{"host_time", "recorded"}});
    ASSERT_FALSE(played.failed) << played.failure;
    expect_played(PixelFormat::kBgr8, 0, cut.complete_chunks);
    EXPECT_TRUE(warned("no summary (the recording was cut off while written?); recovered " +
                       std::to_string(cut.complete_chunks) + " complete chunks"));

    const fs::path repaired = dir_.path() / "repaired.mcap";
    const mcap::RepairResult result = mcap::repair_recording(cut_file, repaired);
    EXPECT_EQ(result.chunks, cut.complete_chunks);
    mcap::McapReader reader(repaired);
    EXPECT_FALSE(reader.recovery());
    ASSERT_TRUE(reader.statistics());
    EXPECT_EQ(reader.chunks().size(), cut.complete_chunks);
    EXPECT_EQ(reader.statistics()->message_count, result.messages);
    EXPECT_EQ(reader.find_attachment("rig.calib.json")->data, read_text(calibration_file_));
    ASSERT_FALSE(play(repaired, {{"host_time", "recorded"}}).failed);
    expect_played(PixelFormat::kBgr8, 0, cut.complete_chunks);
  }
}

TEST_F(McapRecoveryTest, RepairInPlaceAndInfoOfACutFile) {
  const fs::path file = dir_.path() / "cut.mcap";
  copy_prefix(complete_, file, chunks_[3].chunk_start_offset + 100);
  const mcap::RecordingInfo before = mcap::recording_info(file);
  EXPECT_FALSE(before.has_summary);
  EXPECT_EQ(before.readable_bytes, chunks_[3].chunk_start_offset);
  EXPECT_EQ(before.chunk_count, 3u);
  // Frames without truth have no /truth; the rig's 3 messages come with the first frame.
  EXPECT_EQ(before.message_count, 3u + 4u + 2u + 4u);
  EXPECT_NE(mcap::format_info(before).find("summary:     MISSING"), std::string::npos);

  const std::string cut_bytes = read_text(file);
  try {
    mcap::repair_recording(file, dir_.path() / "." / "cut.mcap");
    ADD_FAILURE() << "repaired in place";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("never writes over its input"), std::string::npos)
        << error.what();
  }
  EXPECT_EQ(read_text(file), cut_bytes);

  const fs::path repaired = dir_.path() / "repaired.mcap";
  const mcap::RepairResult result = mcap::repair_recording(file, repaired);
  EXPECT_EQ(result.lost_bytes, 100u);
  ASSERT_EQ(result.dropped.size(), 1u);
  EXPECT_EQ(result.dropped[0].offset, chunks_[3].chunk_start_offset);
  EXPECT_EQ(read_text(file), cut_bytes);
  const mcap::RecordingInfo after = mcap::recording_info(repaired);
  EXPECT_TRUE(after.has_summary);
  EXPECT_TRUE(after.problems.empty());
  EXPECT_EQ(after.message_count, before.message_count);
  EXPECT_EQ(after.start_time_ns, before.start_time_ns);
  EXPECT_EQ(after.end_time_ns, before.end_time_ns);
  EXPECT_FALSE(fs::exists(repaired.string() + ".repairing"));
}

// 4.26 GB asked for by a 1.25 MB file once; larger sizes threw a bare std::bad_alloc.
TEST_F(McapRecoveryTest, AForgedUncompressedSizeIsALocatedErrorThatCostsNoMemory) {
  for (const std::string compression : {"zstd", "lz4", "none"}) {
    SCOPED_TRACE(compression);
    const fs::path file = dir_.path() / (compression + ".mcap");
    ASSERT_FALSE(
        record(file, PixelFormat::kBgr8, {{"chunk_size", 1}, {"compression", compression}}).failed);
    mcap::McapReader reader(file);
    const mcap::ChunkIndex chunk = reader.chunks()[1];
    const std::string place =
        file.string() + ": Chunk at offset " + std::to_string(chunk.chunk_start_offset) + ": ";
    // uncompressed_size: after the prefix, message_start_time and message_end_time.
    const std::uint64_t size_offset = chunk.chunk_start_offset + mcap::kRecordPrefixSize + 16;
    const std::uint64_t peak_before = peak_rss_bytes();
    patch(file, size_offset, u64_bytes(512u << 20));
    try {
      reader.read_chunk(chunk);
      ADD_FAILURE() << "read a chunk with a forged size";
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what()).find(place + "expected 536870912"), std::string::npos)
          << error.what();
    }
    EXPECT_LT(peak_rss_bytes() - peak_before, 64u << 20);
    patch(file, size_offset, u64_bytes(std::uint64_t{1} << 40));
    try {
      reader.read_chunk(chunk);
      ADD_FAILURE() << "read a chunk with a forged size";
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what())
                    .find(place + "uncompressed_size 1099511627776 exceeds "
                                  "1073741824 bytes, the most a chunk may hold"),
                std::string::npos)
          << error.what();
    }
  }
}

// A flipped bit in the summary, the Footer or the closing magic (every byte of the last
// 64, the Footer's, every 8th before) leaves every chunk readable, found by scanning the
// data section.
TEST_F(McapRecoveryTest, AFlippedBitInTheSummaryFallsBackToAScan) {
  const std::string original = read_text(complete_);
  std::uint64_t summary_start = 0;
  std::memcpy(&summary_start, original.data() + original.size() - 8 - 20, 8);
  ASSERT_GT(summary_start, chunks_.back().chunk_start_offset);
  const fs::path file = dir_.path() / "flipped.mcap";
  const std::uint64_t tail = original.size() - 64;
  for (std::uint64_t offset = summary_start; offset < original.size();
       offset += offset < tail ? 8 : 1) {
    SCOPED_TRACE("bit flipped at offset " + std::to_string(offset));
    write_text(file, original);
    flip_bit(file, offset);
    mcap::McapReader reader(file);
    ASSERT_EQ(reader.chunks().size(), chunks_.size());
    std::size_t messages = 0;
    for (const mcap::ChunkIndex& chunk : reader.chunks())
      messages += reader.read_chunk(chunk).size();
    EXPECT_EQ(messages, 3u + 4u + 2u + 4u + 2u + 4u + 2u);  // the rig's, then frames
    EXPECT_EQ(reader.find_attachment("rig.calib.json")->data, read_text(calibration_file_));
  }
  write_text(file, original);
  flip_bit(file, summary_start + 40);
  const RunResult played = play(file, {{"host_time", "recorded"}});
  ASSERT_FALSE(played.failed) << played.failure;
  expect_played(PixelFormat::kBgr8, 0, frames_.size());
  EXPECT_TRUE(warned(file.string() + ": summary not used (" + file.string() +
                     ": summary section at offset " + std::to_string(summary_start) +
                     ": CRC mismatch"));
  EXPECT_NE(mcap::format_info(mcap::recording_info(file)).find("summary:     DAMAGED"),
            std::string::npos);
}

// 3 of 30 chunks were kept once, in place, with exit code 0.
TEST_F(McapRecoveryTest, RepairKeepsEveryIntactChunkAroundADamagedLength) {
  frames_ = make_frames(30, small_calibration(), 3);
  const fs::path file = dir_.path() / "thirty.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8, {{"chunk_size", 1}}).failed);
  const std::vector<mcap::ChunkIndex> chunks = mcap::McapReader(file).chunks();
  ASSERT_EQ(chunks.size(), 30u);
  const mcap::ChunkIndex& damaged = chunks[3];
  const std::string original = read_text(file);
  // Too long for the file, then shorter than the chunk.
  for (const std::uint64_t length : {std::uint64_t{1} << 40, damaged.chunk_length - 100}) {
    SCOPED_TRACE("length " + std::to_string(length));
    write_text(file, original);
    patch(file, damaged.chunk_start_offset + 1, u64_bytes(length));
    const std::string input = read_text(file);

    const mcap::RecordingInfo info = mcap::recording_info(file);
    ASSERT_EQ(info.problems.size(), 1u);
    EXPECT_NE(
        info.problems[0].find("Chunk at offset " + std::to_string(damaged.chunk_start_offset)),
        std::string::npos)
        << info.problems[0];

    const fs::path repaired = dir_.path() / "repaired.mcap";
    const mcap::RepairResult result = mcap::repair_recording(file, repaired);
    EXPECT_EQ(read_text(file), input);
    EXPECT_EQ(result.chunks, 29u);
    ASSERT_EQ(result.dropped.size(), 1u);
    EXPECT_EQ(result.dropped[0].offset, damaged.chunk_start_offset);
    // The chunk and its MessageIndex records, up to the next chunk.
    EXPECT_EQ(result.lost_bytes, chunks[4].chunk_start_offset - damaged.chunk_start_offset);
    EXPECT_TRUE(mcap::recording_info(repaired).problems.empty());
    ASSERT_FALSE(play(repaired, {{"host_time", "recorded"}}).failed);
    std::vector<std::uint64_t> expected;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      if (i != 3) expected.push_back(frames_[i].index);
    }
    EXPECT_EQ(captured_ids(), expected);
  }
}

TEST_F(McapRecoveryTest, InfoAndRepairNameAChunkThatFailsItsCrc) {
  const fs::path file = dir_.path() / "crc.mcap";
  ASSERT_FALSE(
      record(file, PixelFormat::kBgr8, {{"chunk_size", 1}, {"compression", "none"}}).failed);
  const mcap::ChunkIndex chunk = mcap::McapReader(file).chunks()[2];
  flip_bit(file, chunk.chunk_start_offset + chunk.chunk_length - 40);
  const std::string crc_error =
      "Chunk at offset " + std::to_string(chunk.chunk_start_offset) + ": CRC mismatch";

  const mcap::RecordingInfo info = mcap::recording_info(file);
  ASSERT_EQ(info.problems.size(), 1u);
  EXPECT_NE(info.problems[0].find(crc_error), std::string::npos) << info.problems[0];
  EXPECT_NE(
      mcap::format_info(info).find("integrity:   DAMAGED\n  " + file.string() + ": " + crc_error),
      std::string::npos);

  const mcap::RepairResult result = mcap::repair_recording(file, dir_.path() / "repaired.mcap");
  EXPECT_EQ(result.chunks, frames_.size() - 1);
  ASSERT_EQ(result.dropped.size(), 1u);
  EXPECT_EQ(result.dropped[0].offset, chunk.chunk_start_offset);
  EXPECT_EQ(result.lost_bytes, chunk.chunk_length);
  EXPECT_NE(result.dropped[0].reason.find(crc_error), std::string::npos);
}

// Tilth writes no data section CRC (0); a file that has one is checked against it.
TEST_F(McapRecoveryTest, InfoChecksTheDataSectionCrc) {
  const std::optional<mcap::DataEnd> data_end = mcap::McapReader(complete_).data_end();
  ASSERT_TRUE(data_end);
  EXPECT_EQ(data_end->data_section_crc, 0u);
  const std::uint32_t crc = mcap::McapReader(complete_).crc_of(0, data_end->offset);
  std::string crc_bytes(4, '\0');
  std::memcpy(crc_bytes.data(), &crc, 4);
  patch(complete_, data_end->offset + mcap::kRecordPrefixSize, crc_bytes);
  EXPECT_TRUE(mcap::recording_info(complete_).problems.empty());

  // A log time in the first chunk's MessageIndex: nothing else covers it.
  flip_bit(complete_, chunks_[0].chunk_start_offset + chunks_[0].chunk_length + 15);
  const mcap::RecordingInfo info = mcap::recording_info(complete_);
  ASSERT_EQ(info.problems.size(), 1u);
  EXPECT_NE(info.problems[0].find(complete_.string() + ": data section CRC mismatch (stored " +
                                  std::to_string(crc) + " in DataEnd at offset " +
                                  std::to_string(data_end->offset)),
            std::string::npos)
      << info.problems[0];
}

// A stop signal during `tilth recording repair FILE OUTPUT`: FILE and an existing OUTPUT
// are left as they were, and no partial output remains.
TEST_F(McapRecoveryTest, StoppedRepairLeavesTheFilesAsTheyWere) {
  const fs::path file = dir_.path() / "cut.mcap";
  const fs::path output = dir_.path() / "repaired.mcap";
  copy_prefix(complete_, file, chunks_[3].chunk_start_offset + 100);
  copy_prefix(complete_, output, chunks_[1].chunk_start_offset);
  const std::string before = read_text(file);
  const std::string output_before = read_text(output);
  int asked = 0;
  try {
    mcap::repair_recording(file, output, [&asked] { return ++asked == 2; });
    FAIL() << "a stopped repair returned";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()), "repairing " + file.string() +
                                             ": stopped before the repair was complete; " +
                                             output.string() + " is left as it was");
  }
  EXPECT_EQ(asked, 2);  // once per chunk, until it said stop
  EXPECT_EQ(read_text(file), before);
  EXPECT_EQ(read_text(output), output_before);
  EXPECT_FALSE(fs::exists(output.string() + ".repairing"));
}

TEST_F(McapRecoveryTest, CorruptChunkIsReportedWithItsOffset) {
  const fs::path file = dir_.path() / "corrupt.mcap";
  frames_ = make_frames(3, small_calibration(), 3);
  ASSERT_FALSE(
      record(file, PixelFormat::kBgr8, {{"chunk_size", 1}, {"compression", "none"}}).failed);
  const mcap::ChunkIndex chunk = mcap::McapReader(file).chunks()[1];
  {
    std::fstream bytes(file, std::ios::in | std::ios::out | std::ios::binary);
    bytes.seekp(static_cast<std::streamoff>(chunk.chunk_start_offset + chunk.chunk_length - 40));
    const char flipped = static_cast<char>(bytes.peek() ^ 0x01);
    bytes.put(flipped);
  }
  const RunResult played = play(file);
  ASSERT_TRUE(played.failed);
  EXPECT_NE(played.failure.find("Chunk at offset " + std::to_string(chunk.chunk_start_offset) +
                                ": CRC mismatch"),
            std::string::npos)
      << played.failure;
  EXPECT_EQ(captured_ids(), std::vector<std::uint64_t>{3});
}

TEST_F(McapRecoveryTest, NotAnMcapFileFailsBeforeTheGraphRuns) {
  const fs::path file = dir_.write("not.mcap", "hello");
  const std::string error =
      start_error(json({{"nodes",
                         {{"src", {{"type", "mcap.player"}, {"params", {{"path", file.string()}}}}},
                          {"out", {{"type", "test.capture"}}}}},
                        {"edges", json::array({json::array({"src.raw", "out.raw"}),
                                               json::array({"src.color", "out.color"})})}})
                      .dump());
  EXPECT_NE(error.find("not an MCAP file"), std::string::npos) << error;
}

TEST_F(McapRecoveryTest, ImagesInAnotherEncodingFailBeforeTheGraphRuns) {
  const fs::path file = dir_.path() / "json-images.mcap";
  {
    mcap::McapWriter writer(file, {});
    writer.add_attachment(
        {0, 0, "rig.calib.json", "application/json", read_text(calibration_file_)});
    const std::uint16_t schema = writer.add_schema("foxglove.RawImage", "jsonschema", "{}");
    writer.add_channel(schema, "/tof/raw", "json");
    writer.add_channel(schema, "/color/image", "json");
    writer.finish();
  }
  const std::string error =
      start_error(json({{"nodes",
                         {{"src", {{"type", "mcap.player"}, {"params", {{"path", file.string()}}}}},
                          {"out", {{"type", "test.capture"}}}}},
                        {"edges", json::array({json::array({"src.raw", "out.raw"}),
                                               json::array({"src.color", "out.color"})})}})
                      .dump());
  EXPECT_NE(
      error.find(file.string() + ": channel /tof/raw has message encoding 'json'; expected 'cdr' "
                                 "(foxglove_msgs/msg/RawImage as mcap.writer records it)"),
      std::string::npos)
      << error;
}

// `info` prints log times as UTC with milliseconds (truncated, as a clock shows them), and
// none for a recording without messages.
TEST(McapRecordingInfo, LogTimesAreUtcWithMilliseconds) {
  EXPECT_EQ(mcap::utc_time_text(0), "1970-01-01T00:00:00.000Z");
  EXPECT_EQ(mcap::utc_time_text(1'763'800'000'002'000'000), "2025-11-22T08:26:40.002Z");
  EXPECT_EQ(mcap::utc_time_text(1'795'594'672'123'999'999), "2026-11-25T08:17:52.123Z");
  EXPECT_EQ(mcap::utc_time_text(1'709'251'199'999'999'999), "2024-02-29T23:59:59.999Z");

  mcap::RecordingInfo info;
  EXPECT_NE(mcap::format_info(info).find("\nduration:    0.000 s\n"), std::string::npos)
      << mcap::format_info(info);
  info.message_count = 2;
  info.start_time_ns = 1'763'800'000'002'000'000;
  info.end_time_ns = 1'763'800'000'302'000'000;
  EXPECT_NE(mcap::format_info(info).find("\nduration:    0.300 s (log time "
                                         "2025-11-22T08:26:40.002Z to 2025-11-22T08:26:40.302Z)\n"),
            std::string::npos)
      << mcap::format_info(info);
}

}  // namespace
}  // namespace tilth::testing
