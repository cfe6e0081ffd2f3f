#include "mcap/mcap_recording.h"

#include <time.h>

#include <algorithm>
#include <ctime>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "mcap/mcap_reader.h"
#include "mcap/mcap_writer.h"
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

std::string utc_time_text(std::uint64_t time_ns) {
  const auto seconds = static_cast<std::time_t>(time_ns / 1'000'000'000);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  std::ostringstream text;
  text << std::put_time(&utc, "%Y-%m-%dT%H:%M:%S") << '.' << std::setfill('0') << std::setw(3)
       << time_ns / 1'000'000 % 1000 << 'Z';
  return text.str();
}

RecordingInfo recording_info(const std::filesystem::path& file) {
  McapReader reader(file);
  RecordingInfo info;
  info.file_size = reader.file_size();
  info.has_summary = !reader.recovery();
  info.readable_bytes = reader.recovery() ? reader.recovery()->readable_bytes : info.file_size;
  info.library = reader.library();
  info.chunk_count = reader.chunks().size();
  if (const auto& recovery = reader.recovery()) {
    info.stop_reason = recovery->stop_reason;
    info.summary_problem = recovery->summary_problem;
    info.problems.push_back(recovery->summary_problem.empty()
                                ? "no summary (cut off while written?)"
                                : "summary not used: " + recovery->summary_problem);
    for (const DamagedRange& range : recovery->skipped) {
      info.problems.push_back(std::to_string(range.size) + " bytes at offset " +
                              std::to_string(range.offset) + " unreadable: " + range.reason);
    }
  }

  std::map<std::uint16_t, std::uint64_t> counts;
  std::uint64_t start = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t end = 0;
  for (const ChunkIndex& chunk : reader.chunks()) {
    try {
      for (const Message& message : reader.read_chunk(chunk)) {
        ++counts[message.channel_id];
        ++info.message_count;
        start = std::min(start, message.log_time);
        end = std::max(end, message.log_time);
      }
    } catch (const Error& damaged) {
      info.problems.push_back(damaged.what());
    }
  }
  if (info.message_count > 0) {
    info.start_time_ns = start;
    info.end_time_ns = end;
  }
  if (const auto& data_end = reader.data_end(); data_end && data_end->data_section_crc != 0) {
    const std::uint32_t computed = reader.crc_of(0, data_end->offset);
    if (computed != data_end->data_section_crc) {
      info.problems.push_back(file.string() + ": data section CRC mismatch (stored " +
                              std::to_string(data_end->data_section_crc) +
                              " in DataEnd at offset " + std::to_string(data_end->offset) +
                              ", computed " + std::to_string(computed) + ")");
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
    try {
      reader.read_attachment(attachment);
    } catch (const Error& damaged) {
      info.problems.push_back(damaged.what());
    }
  }
  for (const MetadataIndex& metadata : reader.metadata()) {
    info.metadata.push_back(metadata.name);
    try {
      reader.read_metadata(metadata);
    } catch (const Error& damaged) {
      info.problems.push_back(damaged.what());
    }
  }
  return info;
}

std::string format_info(const RecordingInfo& info) {
  std::ostringstream text;
  text << "size:        " << info.file_size << " bytes\n";
  if (info.has_summary) {
    text << "summary:     yes\n";
  } else if (!info.summary_problem.empty()) {
    text << "summary:     DAMAGED (" << info.summary_problem
         << "); read by scanning the data section; `repair` rewrites it\n";
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
  text << "duration:    " << seconds_text(info.duration_s());
  if (info.message_count > 0) {
    text << " (log time " << utc_time_text(info.start_time_ns) << " to "
         << utc_time_text(info.end_time_ns) << ")";
  }
  text << "\n";
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
  text << "\nintegrity:   " << (info.problems.empty() ? "every CRC matches" : "DAMAGED") << "\n";
  for (const std::string& problem : info.problems) text << "  " << problem << "\n";
  return text.str();
}

RepairResult repair_recording(const std::filesystem::path& input,
                              const std::filesystem::path& output,
                              const std::function<bool()>& stopped) {
  namespace fs = std::filesystem;
  std::error_code ignored;
  if (fs::weakly_canonical(input) == fs::weakly_canonical(output) ||
      fs::equivalent(input, output, ignored)) {
    throw Error(output.string() + ": is the file to repair; repair writes a new file and never " +
                "writes over its input");
  }
  McapReader reader(input, McapReader::Index::kScan);
  RepairResult result;
  result.dropped = reader.recovery()->skipped;
  const fs::path temporary = output.string() + ".repairing";
  try {
    WriterOptions options;
    options.compression =
        reader.chunks().empty() ? std::string(kZstd) : reader.chunks().front().compression;
    options.chunk_size = std::numeric_limits<std::uint64_t>::max();  // as the input's chunks
    options.library = reader.library();
    McapWriter writer(temporary, options);
    // Damage in the input is dropped and reported; an error writing the output is not.
    for (const AttachmentIndex& index : reader.attachments()) {
      std::optional<Attachment> attachment;
      try {
        attachment = reader.read_attachment(index);
      } catch (const Error& damaged) {
        result.dropped.push_back({index.offset, index.length, damaged.what()});
        continue;
      }
      writer.add_attachment(*attachment);
    }
    for (const MetadataIndex& index : reader.metadata()) {
      std::optional<Metadata> metadata;
      try {
        metadata = reader.read_metadata(index);
      } catch (const Error& damaged) {
        result.dropped.push_back({index.offset, index.length, damaged.what()});
        continue;
      }
      writer.add_metadata(*metadata);
    }
    // Channels (and their schemas) as the output first needs them: a chunk may define
    // its own.
    std::map<std::uint16_t, std::uint16_t> schema_ids;
    std::map<std::uint16_t, std::uint16_t> channel_ids;
    const auto output_channel = [&](std::uint16_t id) {
      if (const auto known = channel_ids.find(id); known != channel_ids.end()) return known->second;
      const Channel& channel = reader.channels().at(id);
      std::uint16_t schema = 0;
      if (channel.schema_id != 0) {
        if (!schema_ids.contains(channel.schema_id)) {
          const Schema& source = reader.schemas().at(channel.schema_id);
          schema_ids[channel.schema_id] =
              writer.add_schema(source.name, source.encoding, source.data);
        }
        schema = schema_ids.at(channel.schema_id);
      }
      return channel_ids[id] = writer.add_channel(schema, channel.topic, channel.message_encoding,
                                                  channel.metadata);
    };
    for (const auto& [id, channel] : reader.channels()) output_channel(id);
    for (const ChunkIndex& chunk : reader.chunks()) {
      if (stopped()) throw Error("stopped before the repair was complete");
      std::vector<Message> messages;
      try {
        messages = reader.read_chunk(chunk);
        for (const Message& message : messages) {
          if (!reader.channels().contains(message.channel_id)) {
            throw Error(input.string() + ": Chunk at offset " +
                        std::to_string(chunk.chunk_start_offset) + ": a message is on channel " +
                        std::to_string(message.channel_id) + ", which the file does not define");
          }
        }
      } catch (const Error& damaged) {
        result.dropped.push_back({chunk.chunk_start_offset, chunk.chunk_length, damaged.what()});
        continue;
      }
      for (const Message& message : messages) {
        writer.write(output_channel(message.channel_id), message.sequence, message.log_time,
                     message.publish_time, message.data);
      }
      result.messages += messages.size();
      writer.close_chunk();
      ++result.chunks;
    }
    writer.finish();
  } catch (const std::exception& error) {
    fs::remove(temporary, ignored);
    throw Error("repairing " + input.string() + ": " + error.what() + "; " + output.string() +
                " is left as it was");
  }
  fs::rename(temporary, output);
  std::sort(result.dropped.begin(), result.dropped.end(),
            [](const DamagedRange& a, const DamagedRange& b) { return a.offset < b.offset; });
  for (const DamagedRange& range : result.dropped) result.lost_bytes += range.size;
  return result;
}

}  // namespace tilth::mcap
