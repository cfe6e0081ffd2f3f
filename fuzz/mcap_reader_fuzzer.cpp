// Fuzz target: an MCAP file through McapReader, as the player and `tilth recording`
// read it: the summary or the recovery scan, then every chunk, attachment and metadata
// record it indexes. Each unreadable part must end in tilth::Error; a crash, a sanitizer
// report, an allocation beyond the fuzzer's limit or any other exception is a bug.
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fuzz_input_file.h"
#include "mcap/mcap_reader.h"
#include "tilth/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = tilth::fuzzing::write_input("recording.mcap", data, size);
  std::optional<tilth::mcap::McapReader> reader;
  try {
    reader.emplace(file);
  } catch (const tilth::Error&) {
    return 0;
  }
  // One bad record does not keep the reader from the others.
  for (const auto& chunk : reader->chunks()) {
    try {
      reader->read_chunk(chunk);
    } catch (const tilth::Error&) {
    }
  }
  for (const auto& attachment : reader->attachments()) {
    try {
      reader->read_attachment(attachment);
    } catch (const tilth::Error&) {
    }
  }
  for (const auto& metadata : reader->metadata()) {
    try {
      reader->read_metadata(metadata);
    } catch (const tilth::Error&) {
    }
  }
  return 0;
}
