#include "mcap_recording.h"

#include <algorithm>
#include <limits>
#include <map>
#include <sstream>

#include "mcap_reader.h"
#include "mcap_writer.h"
#include "tilth/error.h"

namespace tilth::mcap {
namespace {

std::string seconds_text(double seconds) {
  std::ostringstream text;
  text.precision(3);
  text << std::fixed << seconds << " s";
  return text.str();
}

}  // namespace

RecordingInfo recording_info(const std::filesystem::path& file) {
  McapReader reader(file);
  RecordingInfo info;
  info.file_size = reader.file_size();
  info.has_summary = !reader.recovery();
  info.readable_bytes = reader.recovery() ? reader.recovery()->readable_bytes : info.file_size;
  if (reader.recovery()) info.stop_reason = reader.recovery()->stop_reason;
  info.library = reader.library();
  info.chunk_count = reader.chunks().size();

  std::map<std::uint16_t, std::uint64_t> counts;
  if (reader.statistics()) {
    counts = reader.statistics()->channel_message_counts;
    info.message_count = reader.statistics()->message_count;
    info.start_time_ns = reader.statistics()->message_start_time;
    info.end_time_ns = reader.statistics()->message_end_time;
  } else {
    std::uint64_t start = std::numeric_limits<std::uint64_t>::max();
    std::uint64_t end = 0;
    for (const ChunkIndex& chunk : reader.chunks()) {
      for (const Message& message : reader.read_chunk(chunk)) {
        ++counts[message.channel_id];
        ++info.message_count;
        start = std::min(start, message.log_time);
        end = std::max(end, message.log_time);
      }
    }
    if (info.message_count > 0) {
      info.start_time_ns = start;
      info.end_time_ns = end;
    }
  }
  for (const auto& [id, channel] : reader.channels()) {
    const auto schema = reader.schemas().find(channel.schema_id);
    info.channels.push_back({channel.topic,
                             schema == reader.schemas().end() ? "" : schema->second.name,
                             channel.message_encoding, counts[id]});
  }
  for (const ChunkIndex& chunk : reader.chunks()) {
    const std::string name = chunk.compression.empty() ? "none" : chunk.compression;
    const auto known = std::find_if(info.compressions.begin(), info.compressions.end(),
                                    [&](const auto& entry) { return entry.first == name; });
    if (known == info.compressions.end()) {
      info.compressions.emplace_back(name, 1);
    } else {
      ++known->second;
    }
  }
  for (const AttachmentIndex& attachment : reader.attachments()) {
    info.attachments.push_back(attachment.name);
  }
  for (const MetadataIndex& metadata : reader.metadata()) info.metadata.push_back(metadata.name);
  return info;
}

std::string format_info(const RecordingInfo& info) {
  std::ostringstream text;
  text << "size:        " << info.file_size << " bytes\n";
  if (info.has_summary) {
    text << "summary:     yes\n";
  } else {
    text << "summary:     MISSING; readable " << info.readable_bytes << " of " << info.file_size
         << " bytes (" << info.stop_reason << "); `repair` rewrites it\n";
  }
  text << "library:     " << info.library << "\n";
  text << "messages:    " << info.message_count << " in " << info.chunk_count << " chunks\n";
  std::string compressions;
  for (const auto& [name, chunks] : info.compressions) {
    compressions += (compressions.empty() ? "" : ", ") + name;
    if (info.compressions.size() > 1) compressions += " (" + std::to_string(chunks) + " chunks)";
  }
  text << "compression: " << (compressions.empty() ? "-" : compressions) << "\n";
  text << "duration:    " << seconds_text(info.duration_s()) << " (log time " << info.start_time_ns
       << " to " << info.end_time_ns << " ns)\n";
  text << "channels:\n";
  for (const ChannelInfo& channel : info.channels) {
    text << "  " << channel.topic << "  " << channel.message_count << " messages  "
         << (channel.schema.empty() ? "-" : channel.schema) << " (" << channel.message_encoding
         << ")\n";
  }
  text << "attachments:";
  for (const std::string& name : info.attachments) text << " " << name;
  text << "\nmetadata:   ";
  for (const std::string& name : info.metadata) text << " " << name;
  text << "\n";
  return text.str();
}

namespace {

// repair_recording's copy of `reader`'s complete records into `temporary`.
RepairResult copy_complete_records(McapReader& reader, const std::filesystem::path& input,
                                   const std::filesystem::path& temporary,
                                   const std::function<bool()>& stopped) {
  RepairResult result;
  WriterOptions options;
  options.compression =
      reader.chunks().empty() ? std::string(kZstd) : reader.chunks().front().compression;
  options.chunk_size = std::numeric_limits<std::uint64_t>::max();  // as the input's chunks
  options.library = reader.library();
  McapWriter writer(temporary, options);
  for (const AttachmentIndex& index : reader.attachments()) {
    writer.add_attachment(reader.read_attachment(index));
  }
  for (const MetadataIndex& index : reader.metadata()) {
    writer.add_metadata(reader.read_metadata(index));
  }
  std::map<std::uint16_t, std::uint16_t> schema_ids;
  for (const auto& [id, schema] : reader.schemas()) {
    schema_ids[id] = writer.add_schema(schema.name, schema.encoding, schema.data);
  }
  std::map<std::uint16_t, std::uint16_t> channel_ids;
  for (const auto& [id, channel] : reader.channels()) {
    const std::uint16_t schema = channel.schema_id == 0 ? 0 : schema_ids.at(channel.schema_id);
    channel_ids[id] =
        writer.add_channel(schema, channel.topic, channel.message_encoding, channel.metadata);
  }
  for (const ChunkIndex& chunk : reader.chunks()) {
    if (stopped()) throw Error("stopped before the repair was complete");
    for (const Message& message : reader.read_chunk(chunk)) {
      const auto channel = channel_ids.find(message.channel_id);
      if (channel == channel_ids.end()) {
        throw Error(input.string() + ": a message of chunk at offset " +
                    std::to_string(chunk.chunk_start_offset) + " is on channel " +
                    std::to_string(message.channel_id) + ", which the file does not define");
      }
      writer.write(channel->second, message.sequence, message.log_time, message.publish_time,
                   message.data);
      ++result.messages;
    }
    writer.close_chunk();
    ++result.chunks;
  }
  writer.finish();
  if (reader.recovery()) result.lost_bytes = reader.file_size() - reader.recovery()->readable_bytes;
  return result;
}

}  // namespace

RepairResult repair_recording(const std::filesystem::path& input,
                              const std::filesystem::path& output,
                              const std::function<bool()>& stopped) {
  McapReader reader(input);
  const std::filesystem::path temporary = output.string() + ".repairing";
  RepairResult result;
  try {
    result = copy_complete_records(reader, input, temporary, stopped);
  } catch (const std::exception& error) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw Error("repairing " + input.string() + ": " + error.what() + "; " + output.string() +
                " is left as it was");
  }
  std::filesystem::rename(temporary, output);
  return result;
}

}  // namespace tilth::mcap
