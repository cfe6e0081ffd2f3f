// Reads an MCAP file. With a summary section it takes the schemas, channels and the
// chunk, attachment and metadata indexes from there; without one (a file cut off while
// it was written) it scans the data section from the start and keeps everything up to
// the last complete record, saying where and why the scan stopped.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mcap_format.h"

namespace tilth::mcap {

// How a file without a summary was read.
struct Recovery {
  std::uint64_t readable_bytes = 0;  // from the start of the file to the last complete record
  std::string stop_reason;           // why the scan stopped there
};

class McapReader {
 public:
  explicit McapReader(std::filesystem::path file);

  const std::filesystem::path& file() const { return file_; }
  std::uint64_t file_size() const { return file_size_; }
  // Empty when the summary was read; otherwise what the sequential scan recovered.
  const std::optional<Recovery>& recovery() const { return recovery_; }
  const std::string& library() const { return library_; }

  const std::map<std::uint16_t, Schema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, Channel>& channels() const { return channels_; }
  // In file order.
  const std::vector<ChunkIndex>& chunks() const { return chunks_; }
  const std::vector<AttachmentIndex>& attachments() const { return attachments_; }
  const std::vector<MetadataIndex>& metadata() const { return metadata_; }
  // From the summary; empty for a recovered file.
  const std::optional<Statistics>& statistics() const { return statistics_; }

  // The chunk's messages in the order written. Throws tilth::Error with the chunk's
  // file offset when it is unreadable or its CRC does not match.
  std::vector<Message> read_chunk(const ChunkIndex& chunk);
  Attachment read_attachment(const AttachmentIndex& index);
  Metadata read_metadata(const MetadataIndex& index);
  // The first attachment named `name`, if any.
  std::optional<Attachment> find_attachment(std::string_view name);

 private:
  std::string read_bytes(std::uint64_t offset, std::uint64_t size);
  std::string where(std::string_view record, std::uint64_t offset) const;
  bool read_summary();
  void scan();
  void add_channel(Channel channel, std::uint64_t offset);

  const std::filesystem::path file_;
  std::ifstream in_;
  std::uint64_t file_size_ = 0;
  std::string library_;
  std::uint64_t data_start_ = 0;  // after the Header
  std::optional<Recovery> recovery_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::vector<ChunkIndex> chunks_;
  std::vector<AttachmentIndex> attachments_;
  std::vector<MetadataIndex> metadata_;
  std::optional<Statistics> statistics_;
};

}  // namespace tilth::mcap
