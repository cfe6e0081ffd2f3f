// Writes an MCAP file: Header, then schemas, channels, attachments and metadata as they
// are added, messages in compressed chunks each followed by its MessageIndex records,
// and on finish() DataEnd, the summary section, SummaryOffset records and the Footer.
// Closed chunks are compressed (and their CRC computed) on background threads, off the
// thread that adds messages, and written, in order, as they complete;
// each is flushed to the file when written, so a process killed mid-write leaves a file
// that is readable up to its last written chunk. A write that fails (a full disk) ends
// the writer: the file is cut back to its last complete record, and every call after
// it throws the same error.
#pragma once

#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <string>
#include <vector>

#include "mcap/mcap_format.h"

namespace tilth::mcap {

struct WriterOptions {
  std::string compression = std::string(kZstd);  // "zstd", "lz4" or "" (none)
  // A chunk is closed by close_chunk_if_full() once it holds this many bytes.
  std::uint64_t chunk_size = 4 * 1024 * 1024;
  // Closed chunks compressed at once, each on a thread of its own.
  std::size_t chunks_in_flight = 2;
  // false: close_chunk() waits while more than chunks_in_flight closed chunks are not
  // yet written. true (a live recording): a chunk closed while chunks_in_flight others
  // are still being compressed is stored uncompressed instead, so the recording keeps
  // up with its cameras when the CPU cannot compress everything; close_chunk() waits
  // only while more than max_queued_chunks are not yet written.
  bool store_when_behind = false;
  std::size_t max_queued_chunks = 8;
  std::string profile;  // the Header's profile; "" = none of the well-known ones
  std::string library = "tilth";
};

class McapWriter {
 public:
  // Creates (or replaces) the file and writes the magic and the Header.
  McapWriter(std::filesystem::path file, WriterOptions options);
  // Waits for the background compressions; a writer not finished leaves the file as a
  // process killed after the last written chunk would.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Each returns the id the file uses.
  std::uint16_t add_schema(const std::string& name, const std::string& encoding,
                           const std::string& data);
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic,
                            const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata = {});
  void add_attachment(const Attachment& attachment);
  void add_metadata(const Metadata& metadata);

  // Into the open chunk.
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
             std::uint64_t publish_time, std::string_view data);
  // Closes the open chunk when it has reached chunk_size: call between messages that
  // belong in one chunk (a frame's images).
  void close_chunk_if_full();
  // Hands the open chunk, if it has messages, to a background compression (or, behind,
  // stores it uncompressed; see WriterOptions); writes the closed chunks that are ready,
  // oldest first, and waits for the oldest while too many are queued.
  void close_chunk();
  // Closes the open chunk and writes every pending one with its MessageIndex records.
  void flush();
  // Closes the open chunk and writes DataEnd, the summary and the Footer. The writer
  // accepts nothing after it.
  void finish();

  std::uint64_t bytes_written() const { return offset_; }
  // Messages in chunks written to the file (and flushed).
  std::uint64_t messages_written() const { return messages_written_; }

 private:
  // Writes to the file, counting the offset.
  void put(std::string_view bytes);
  // Flushes the file, which then ends with a complete record.
  void flush_file();
  // Ends the writer: closes the file, cuts it back to its last complete record and
  // throws Error(failure_).
  [[noreturn]] void fail(const std::string& what);
  void check_open(std::string_view what) const;
  struct ClosedChunk;
  void write_chunk(ClosedChunk chunk);
  void write_oldest_chunk();

  const std::filesystem::path file_;
  const WriterOptions options_;
  std::ofstream out_;
  std::uint64_t offset_ = 0;
  std::uint64_t complete_size_ = 0;  // the file's size at its last complete, flushed record
  std::uint64_t messages_written_ = 0;
  bool finished_ = false;
  std::string failure_;  // why writing stopped; "" while it goes on

  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::vector<ChunkIndex> chunk_indexes_;
  std::vector<AttachmentIndex> attachment_indexes_;
  std::vector<MetadataIndex> metadata_indexes_;
  Statistics statistics_;

  // The open chunk.
  std::string chunk_records_;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  std::uint64_t chunk_messages_ = 0;
  // Per channel: (log_time, offset in chunk_records_) of each message.
  using MessageOffsets =
      std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>>;
  MessageOffsets chunk_index_;

  // A chunk closed and not yet written: its records compressed (on a thread of its own),
  // or stored as they are (when written), and their CRC.
  struct ChunkData {
    std::string bytes;
    std::uint32_t uncompressed_crc = 0;
  };
  struct ClosedChunk {
    std::uint64_t start_time = 0;
    std::uint64_t end_time = 0;
    std::uint64_t uncompressed_size = 0;
    std::uint64_t messages = 0;
    std::string compression;
    MessageOffsets index;
    std::future<ChunkData> data;
  };
  std::size_t compressing() const;
  std::deque<ClosedChunk> closed_;
};

}  // namespace tilth::mcap
