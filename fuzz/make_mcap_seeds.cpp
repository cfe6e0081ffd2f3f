// Writes the seed corpus of the mcap_reader fuzz target with Tilth's own McapWriter:
// small files that reach every part of the reader (summary or recovery scan, each chunk
// compression, attachments, metadata), so the fuzzer starts from valid structure.
// usage: fuzz_mcap_seeds FOLDER   (the committed seeds: fuzz/corpus/mcap_reader)
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "mcap/mcap_writer.h"

namespace fs = std::filesystem;
using namespace tilth::mcap;

namespace {

// Two chunks of two messages on two channels, an attachment and a metadata record;
// finished (with a summary) or left as a process killed after the last chunk leaves it.
void write_seed(const fs::path& file, const std::string& compression, bool finish) {
  WriterOptions options;
  options.compression = compression;
  options.chunk_size = 64;
  McapWriter writer(file, options);
  const auto schema = writer.add_schema("tilth.GroundTruth", "jsonschema", R"({"type":"object"})");
  const auto truth = writer.add_channel(schema, "/truth", "json", {{"unit", "mm"}});
  const auto raw = writer.add_channel(0, "/raw", "application/octet-stream");
  writer.add_attachment({.log_time = 5,
                         .create_time = 6,
                         .name = "rig.calib.json",
                         .media_type = "application/json",
                         .data = R"({"format":"tilth-calibration/1"})"});
  writer.add_metadata({.name = "recording", .values = {{"rig", "paper"}, {"frames", "4"}}});
  for (std::uint32_t frame = 0; frame < 4; ++frame) {
    const std::uint64_t time = 1'000'000'000ULL + frame * 100'000'000ULL;
    writer.write(truth, frame, time, time + 1, R"({"distance_mm":512.5})");
    writer.write(raw, frame, time, time + 2, std::string(24, static_cast<char>('a' + frame)));
    if (frame % 2 == 1) writer.close_chunk();
  }
  if (finish) writer.finish();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FOLDER\n", argv[0]);
    return 2;
  }
  const fs::path folder = argv[1];
  fs::create_directories(folder);
  write_seed(folder / "zstd.mcap", std::string(kZstd), true);
  write_seed(folder / "lz4.mcap", std::string(kLz4), true);
  write_seed(folder / "stored.mcap", "", true);
  write_seed(folder / "no_summary.mcap", "", false);
  // Cut inside the second chunk: the recovery scan keeps the first.
  const auto whole = folder / "stored.mcap";
  std::string bytes(fs::file_size(whole), '\0');
  std::ifstream(whole, std::ios::binary)
      .read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::ofstream(folder / "cut.mcap", std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  return 0;
}
