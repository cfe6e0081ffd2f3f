// What the command line does with an MCAP recording: `tilth recording info FILE` and
// `tilth recording repair FILE`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tilth::mcap {

struct ChannelInfo {
  std::string topic;
  std::string schema;  // "" = none
  std::string message_encoding;
  std::uint64_t message_count = 0;
};

struct RecordingInfo {
  std::uint64_t file_size = 0;
  bool has_summary = false;
  // Without a summary: the bytes from the start that are readable, and why the rest is not.
  std::uint64_t readable_bytes = 0;
  std::string stop_reason;
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

// From the summary when the file has one; otherwise by reading every recoverable chunk.
RecordingInfo recording_info(const std::filesystem::path& file);
// Lines of text for a terminal.
std::string format_info(const RecordingInfo& info);

struct RepairResult {
  std::uint64_t chunks = 0;
  std::uint64_t messages = 0;
  std::uint64_t lost_bytes = 0;  // after the last complete record of the input
};

// Writes `output` (which may be `input`: it is then replaced once complete) with the
// attachments, metadata, channels and every complete chunk of `input`, chunk by chunk
// as they were, and a summary. Writes OUTPUT.repairing first and renames it; on an error,
// or when `stopped` returns true (asked between chunks), removes it, leaves `output` as
// it was and throws tilth::Error.
RepairResult repair_recording(
    const std::filesystem::path& input, const std::filesystem::path& output,
    const std::function<bool()>& stopped = [] { return false; });

}  // namespace tilth::mcap
