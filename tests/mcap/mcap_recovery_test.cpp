// A recording cut off mid-write (power loss, kill -9) plays up to its last complete
// chunk with a warning saying how much was recovered, and `repair` rewrites it with a
// summary; a chunk whose CRC does not match is reported with its file offset.
#include <fstream>

#include "mcap_fixture.h"
#include "mcap_reader.h"
#include "mcap_recording.h"
#include "mcap_writer.h"
#include "tilth/error.h"

namespace tilth::testing {
namespace {

using nlohmann::json;

void copy_prefix(const fs::path& from, const fs::path& to, std::uint64_t size) {
  std::string bytes = read_text(from);
  ASSERT_LE(size, bytes.size());
  std::ofstream(to, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(size));
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
  EXPECT_EQ(before.message_count, 4u + 2u + 4u);  // frames without truth have no /truth
  EXPECT_NE(mcap::format_info(before).find("summary:     MISSING"), std::string::npos);

  const mcap::RepairResult result = mcap::repair_recording(file, file);
  EXPECT_EQ(result.lost_bytes, 100u);
  const mcap::RecordingInfo after = mcap::recording_info(file);
  EXPECT_TRUE(after.has_summary);
  EXPECT_EQ(after.message_count, before.message_count);
  EXPECT_EQ(after.start_time_ns, before.start_time_ns);
  EXPECT_EQ(after.end_time_ns, before.end_time_ns);
  EXPECT_FALSE(fs::exists(file.string() + ".repairing"));
}

// A stop signal during `tilth recording repair FILE`: FILE is left as it was, and no
// partial output remains.
TEST_F(McapRecoveryTest, StoppedRepairLeavesTheFileAsItWas) {
  const fs::path file = dir_.path() / "cut.mcap";
  copy_prefix(complete_, file, chunks_[3].chunk_start_offset + 100);
  const std::string before = read_text(file);
  int asked = 0;
  try {
    mcap::repair_recording(file, file, [&asked] { return ++asked == 2; });
    FAIL() << "a stopped repair returned";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()), "repairing " + file.string() +
                                             ": stopped before the repair was complete; " +
                                             file.string() + " is left as it was");
  }
  EXPECT_EQ(asked, 2);  // once per chunk, until it said stop
  EXPECT_EQ(read_text(file), before);
  EXPECT_FALSE(fs::exists(file.string() + ".repairing"));
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

}  // namespace
}  // namespace tilth::testing
