// What the command line does with an MCAP recording: `tilth recording info FILE`, which
// checks every CRC, and `tilth recording repair FILE OUTPUT`, which salvages every
// intact chunk into a new file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mcap/mcap_reader.h"

namespace tilth::mcap {

struct ChannelInfo {
  std::string topic;
  std::string schema;  // "" = none
  std::string message_encoding;
  std::uint64_t message_count = 0;
};

struct RecordingInfo {
  std::uint64_t file_size = 0;
  bool has_summary = false;     // read from an intact summary
  std::string summary_problem;  // why a summary the file has was not used; "" = none
  // Without a summary: the bytes from the start that are readable, and why the rest is not.
  std::uint64_t readable_bytes = 0;
  std::string stop_reason;
  // Everything that keeps the file from being intact, one line each: a missing or
  // damaged summary, damaged bytes the scan skipped, chunks, attachments or metadata
  // that fail their CRC or cannot be read, a data section CRC that does not match.
  std::vector<std::string> problems;
  std::string library;
  std::vector<ChannelInfo> channels;
  std::uint64_t message_count = 0;
  std::uint64_t chunk_count = 0;
  std::uint64_t start_time_ns = 0;  // log times of the first and last message
  std::uint64_t end_time_ns = 0;
  // How many chunks each compression holds ("none" for stored chunks), in first-seen order.
  std::vector<std::pair<std::string, std::uint64_t>> compressions;
  std::vector<std::string> attachments;
  std::vector<std::string> metadata;

  double duration_s() const { return static_cast<double>(end_time_ns - start_time_ns) * 1e-9; }
};

// Reads every chunk, attachment and metadata record (checking their CRCs) and the data
// section's CRC when the file has one; the indexes from the summary when it is intact,
// otherwise from a scan of the data section.
RecordingInfo recording_info(const std::filesystem::path& file);
// Lines of text for a terminal.
std::string format_info(const RecordingInfo& info);
// A log time (nanoseconds since the Unix epoch) as UTC in ISO 8601 with milliseconds,
// truncated: 2026-11-25T08:17:52.123Z.
std::string utc_time_text(std::uint64_t time_ns);

struct RepairResult {
  std::uint64_t chunks = 0;
  std::uint64_t messages = 0;
  // What of the input the output lacks, in file order: damaged or cut-off bytes, chunks
  // that fail their CRC, unreadable attachments and metadata.
  std::vector<DamagedRange> dropped;
  std::uint64_t lost_bytes = 0;  // their total
};

// Writes `output` with the attachments, metadata, channels and every intact chunk of
// `input`, found by scanning its data section (resynchronising after damage; the
// summary is not trusted), chunk by chunk as they were, and a summary. The output is
// written beside itself (OUTPUT.repairing) and renamed into place once complete;
// `output` may not be `input`: the input is never written. On an error, or when
// `stopped` returns true (asked between chunks), removes the partial output, leaves
// `output` as it was and throws tilth::Error.
RepairResult repair_recording(
    const std::filesystem::path& input, const std::filesystem::path& output,
    const std::function<bool()>& stopped = [] { return false; });

}  // namespace tilth::mcap
