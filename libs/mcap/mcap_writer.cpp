#include "mcap/mcap_writer.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>

#include "mcap/compression.h"
#include "mcap/crc32.h"
#include "mcap/record_codec.h"
#include "tilth/error.h"

namespace tilth::mcap {
namespace {

std::string_view magic() { return {kMagic.data(), kMagic.size()}; }

// Opcode and content length of a record whose content is written separately.
std::string record_prefix(Opcode opcode, std::uint64_t content_size) {
  RecordBuilder prefix;
  prefix.u8(static_cast<std::uint8_t>(opcode)).u64(content_size);
  return prefix.content();
}

// Compression is best effort, recording is not: a compression thread yields the CPU to
// the thread that adds messages (and so to the cameras' frames), which stores the chunks
// it could not compress in time (store_when_behind). Linux gives each thread its nice
// value.
void lower_this_thread_priority() {
  constexpr int kCompressionNice = 10;
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kCompressionNice);
}

std::string summary_offset(Opcode group, std::uint64_t start, std::uint64_t length) {
  return RecordBuilder()
      .u8(static_cast<std::uint8_t>(group))
      .u64(start)
      .u64(length)
      .record(Opcode::kSummaryOffset);
}

}  // namespace

McapWriter::McapWriter(std::filesystem::path file, WriterOptions options)
    : file_(std::move(file)), options_(std::move(options)) {
  if (options_.compression != kZstd && options_.compression != kLz4 &&
      !options_.compression.empty()) {
    throw Error(file_.string() + ": compression '" + options_.compression +
                "' is not supported; expected zstd, lz4 or none");
  }
  out_.open(file_, std::ios::binary | std::ios::trunc);
  if (!out_) {
    throw Error(file_.string() + ": cannot create the file: " + std::strerror(errno));
  }
  put(magic());
  put(RecordBuilder().string(options_.profile).string(options_.library).record(Opcode::kHeader));
  flush_file();
}

void McapWriter::check_open(std::string_view what) const {
  if (!failure_.empty()) throw Error(failure_);
  if (finished_) throw Error(file_.string() + ": " + std::string(what) + " after finish()");
}

void McapWriter::put(std::string_view bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_)
    fail("cannot write at offset " + std::to_string(offset_) + ": " + std::strerror(errno));
  offset_ += bytes.size();
}

void McapWriter::flush_file() {
  out_.flush();
  if (!out_)
    fail("cannot write before offset " + std::to_string(offset_) + ": " + std::strerror(errno));
  complete_size_ = offset_;
}

void McapWriter::fail(const std::string& what) {
  failure_ = file_.string() + ": " + what + "; writing stopped, the file keeps its first " +
             std::to_string(complete_size_) + " bytes (" + std::to_string(messages_written_) +
             " messages) without a summary";
  out_.close();
  std::error_code error;
  std::filesystem::resize_file(file_, complete_size_, error);
  if (error) failure_ += " and could not be cut back to them: " + error.message();
  throw Error(failure_);
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding,
                                     const std::string& data) {
  check_open("add_schema");
  flush();
  Schema schema{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  put(encode(schema));
  schemas_.push_back(std::move(schema));
  return schemas_.back().id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  check_open("add_channel");
  flush();
  Channel channel{static_cast<std::uint16_t>(channels_.size()), schema_id, topic, message_encoding,
                  metadata};
  put(encode(channel));
  channels_.push_back(std::move(channel));
  return channels_.back().id;
}

void McapWriter::add_attachment(const Attachment& attachment) {
  check_open("add_attachment");
  flush();
  const std::string record = encode(attachment);
  attachment_indexes_.push_back({offset_, record.size(), attachment.log_time,
                                 attachment.create_time, attachment.data.size(), attachment.name,
                                 attachment.media_type});
  put(record);
  flush_file();
}

void McapWriter::add_metadata(const Metadata& metadata) {
  check_open("add_metadata");
  flush();
  const std::string record = encode(metadata);
  metadata_indexes_.push_back({offset_, record.size(), metadata.name});
  put(record);
  flush_file();
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                       std::uint64_t publish_time, std::string_view data) {
  check_open("write");
  if (channel_id >= channels_.size()) {
    throw Error(file_.string() + ": message on channel " + std::to_string(channel_id) +
                ", which was not added");
  }
  if (chunk_records_.empty()) {
    chunk_start_time_ = log_time;
    chunk_end_time_ = log_time;
  }
  chunk_start_time_ = std::min(chunk_start_time_, log_time);
  chunk_end_time_ = std::max(chunk_end_time_, log_time);
  chunk_index_[channel_id].emplace_back(log_time, chunk_records_.size());

  RecordBuilder head;
  head.u16(channel_id).u32(sequence).u64(log_time).u64(publish_time);
  chunk_records_.append(record_prefix(Opcode::kMessage, head.content().size() + data.size()));
  chunk_records_.append(head.content());
  chunk_records_.append(data);
  ++chunk_messages_;

  if (statistics_.message_count == 0) {
    statistics_.message_start_time = log_time;
    statistics_.message_end_time = log_time;
  }
  ++statistics_.message_count;
  ++statistics_.channel_message_counts[channel_id];
  statistics_.message_start_time = std::min(statistics_.message_start_time, log_time);
  statistics_.message_end_time = std::max(statistics_.message_end_time, log_time);
}

void McapWriter::close_chunk_if_full() {
  if (chunk_records_.size() >= options_.chunk_size) close_chunk();
}

std::size_t McapWriter::compressing() const {
  return static_cast<std::size_t>(std::count_if(closed_.begin(), closed_.end(), [](const auto& c) {
    return !c.compression.empty() &&
           c.data.wait_for(std::chrono::seconds(0)) == std::future_status::timeout;
  }));
}

void McapWriter::close_chunk() {
  check_open("close_chunk");
  if (!chunk_records_.empty()) {
    ClosedChunk chunk;
    chunk.start_time = chunk_start_time_;
    chunk.end_time = chunk_end_time_;
    chunk.uncompressed_size = chunk_records_.size();
    chunk.messages = std::exchange(chunk_messages_, 0);
    chunk.index = std::move(chunk_index_);
    const bool behind = options_.store_when_behind && compressing() >= options_.chunks_in_flight;
    chunk.compression = behind ? "" : options_.compression;
    // Stored chunks are deferred: their CRC is computed when they are written.
    chunk.data = std::async(
        chunk.compression.empty() ? std::launch::deferred : std::launch::async,
        [compression = chunk.compression, records = std::move(chunk_records_)]() mutable {
          if (!compression.empty()) lower_this_thread_priority();
          const std::uint32_t crc = crc32(records);
          return ChunkData{
              compression.empty() ? std::move(records) : compress(compression, records), crc};
        });
    closed_.push_back(std::move(chunk));
    chunk_records_.clear();
    chunk_index_.clear();
  }
  const std::size_t limit =
      options_.store_when_behind ? options_.max_queued_chunks : options_.chunks_in_flight;
  while (!closed_.empty() &&
         (closed_.size() > limit ||
          closed_.front().data.wait_for(std::chrono::seconds(0)) != std::future_status::timeout)) {
    write_oldest_chunk();
  }
}

void McapWriter::flush() {
  check_open("flush");
  close_chunk();
  while (!closed_.empty()) write_oldest_chunk();
}

void McapWriter::write_oldest_chunk() {
  ClosedChunk chunk = std::move(closed_.front());
  closed_.pop_front();
  write_chunk(std::move(chunk));
}

McapWriter::~McapWriter() {
  for (ClosedChunk& chunk : closed_) {
    if (!chunk.compression.empty()) chunk.data.wait();
  }
}

void McapWriter::write_chunk(ClosedChunk chunk) {
  ChunkData data;
  try {
    data = chunk.data.get();
  } catch (const std::exception& error) {
    fail("compressing the chunk of messages from " + std::to_string(chunk.start_time) +
         " ns failed: " + error.what());
  }
  const std::string& compressed = data.bytes;
  RecordBuilder head;
  head.u64(chunk.start_time)
      .u64(chunk.end_time)
      .u64(chunk.uncompressed_size)
      .u32(data.uncompressed_crc)
      .string(chunk.compression)
      .u64(compressed.size());

  ChunkIndex index;
  index.message_start_time = chunk.start_time;
  index.message_end_time = chunk.end_time;
  index.chunk_start_offset = offset_;
  index.compression = chunk.compression;
  index.compressed_size = compressed.size();
  index.uncompressed_size = chunk.uncompressed_size;
  put(record_prefix(Opcode::kChunk, head.content().size() + compressed.size()));
  put(head.content());
  put(compressed);
  index.chunk_length = offset_ - index.chunk_start_offset;

  const std::uint64_t indexes_start = offset_;
  for (const auto& [channel_id, entries] : chunk.index) {
    RecordBuilder entry_bytes;
    for (const auto& [time, position] : entries) entry_bytes.u64(time).u64(position);
    index.message_index_offsets[channel_id] = offset_;
    put(RecordBuilder()
            .u16(channel_id)
            .bytes32(entry_bytes.content())
            .record(Opcode::kMessageIndex));
  }
  index.message_index_length = offset_ - indexes_start;
  flush_file();
  messages_written_ += chunk.messages;
  chunk_indexes_.push_back(std::move(index));
}

void McapWriter::finish() {
  check_open("finish");
  flush();
  // data_section_crc 0: not computed. It would be a pass over every byte on the
  // recording's thread; chunks, attachments and the summary carry CRCs of their own.
  put(RecordBuilder().u32(0).record(Opcode::kDataEnd));

  // The summary is built in memory: its CRC covers it up to the Footer's offsets.
  const std::uint64_t summary_start = offset_;
  std::string summary;
  std::string offsets;
  const auto group = [&](Opcode opcode, const auto& records) {
    if (records.empty()) return;
    const std::uint64_t start = summary_start + summary.size();
    for (const auto& record : records) summary += encode(record);
    offsets += summary_offset(opcode, start, summary_start + summary.size() - start);
  };
  group(Opcode::kSchema, schemas_);
  group(Opcode::kChannel, channels_);
  statistics_.schema_count = static_cast<std::uint16_t>(schemas_.size());
  statistics_.channel_count = static_cast<std::uint32_t>(channels_.size());
  statistics_.attachment_count = static_cast<std::uint32_t>(attachment_indexes_.size());
  statistics_.metadata_count = static_cast<std::uint32_t>(metadata_indexes_.size());
  statistics_.chunk_count = static_cast<std::uint32_t>(chunk_indexes_.size());
  group(Opcode::kStatistics, std::vector<Statistics>{statistics_});
  group(Opcode::kChunkIndex, chunk_indexes_);
  group(Opcode::kAttachmentIndex, attachment_indexes_);
  group(Opcode::kMetadataIndex, metadata_indexes_);

  const std::uint64_t summary_offset_start = summary_start + summary.size();
  std::string tail = summary + offsets;
  tail += record_prefix(Opcode::kFooter, kFooterContentSize);
  tail += RecordBuilder().u64(summary_start).u64(summary_offset_start).content();
  const std::uint32_t summary_crc = crc32(tail);
  tail += RecordBuilder().u32(summary_crc).content();
  tail += magic();
  put(tail);
  out_.close();
  if (!out_) fail(std::string("cannot write the summary: ") + std::strerror(errno));
  finished_ = true;
}

}  // namespace tilth::mcap
