// Reads an MCAP file. With an intact summary section it takes the schemas, channels and
// the chunk, attachment and metadata indexes from there. Without one (a file cut off
// while it was written), or when the Footer or summary is damaged, it scans the data
// section from the Header on, as the MCAP spec lets every reader do: it keeps every
// intact record, resynchronises on the next chunk whose CRC matches after a damaged
// one, and says which bytes it skipped and why. Every length read from the file is
// checked against the bytes the file has before anything is allocated for it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mcap/mcap_format.h"

namespace tilth::mcap {

// Bytes of the file a scan could not read, and why.
struct DamagedRange {
  std::uint64_t offset = 0;
  std::uint64_t size = 0;
  std::string reason;
};

// How a file was read without its summary.
struct Recovery {
  // Why the summary was not used: "" when the file has none (cut off while written),
  // else what is wrong with the Footer or the summary.
  std::string summary_problem;
  std::uint64_t readable_bytes = 0;  // from the start to the end of the last intact record
  std::string stop_reason;           // why the scan stopped there
  // What the scan skipped, in file order: damaged records between intact ones and, when
  // the data section does not end with a DataEnd record, the rest of the file.
  std::vector<DamagedRange> skipped;
};

// The DataEnd record: where it is and the data section's CRC (0 = not recorded).
struct DataEnd {
  std::uint64_t offset = 0;
  std::uint32_t data_section_crc = 0;
};

class McapReader {
 public:
  // kSummary reads the summary when it is intact; kScan always scans the data section
  // (`tilth recording repair`, which trusts nothing but CRC-checked chunks).
  enum class Index { kSummary, kScan };

  explicit McapReader(std::filesystem::path file, Index index = Index::kSummary);

  const std::filesystem::path& file() const { return file_; }
  std::uint64_t file_size() const { return file_size_; }
  // Empty when the summary was read; otherwise what the scan recovered.
  const std::optional<Recovery>& recovery() const { return recovery_; }
  const std::string& library() const { return library_; }
  const std::optional<DataEnd>& data_end() const { return data_end_; }

  const std::map<std::uint16_t, Schema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, Channel>& channels() const { return channels_; }
  // In file order.
  const std::vector<ChunkIndex>& chunks() const { return chunks_; }
  const std::vector<AttachmentIndex>& attachments() const { return attachments_; }
  const std::vector<MetadataIndex>& metadata() const { return metadata_; }
  // From the summary; empty for a scanned file.
  const std::optional<Statistics>& statistics() const { return statistics_; }

  // The chunk's messages in the order written. Throws tilth::Error with the chunk's
  // file offset when it is unreadable or its CRC does not match.
  std::vector<Message> read_chunk(const ChunkIndex& chunk);
  Attachment read_attachment(const AttachmentIndex& index);
  Metadata read_metadata(const MetadataIndex& index);
  // The first attachment named `name`, if any.
  std::optional<Attachment> find_attachment(std::string_view name);
  // The CRC-32 of the bytes [begin, end) of the file.
  std::uint32_t crc_of(std::uint64_t begin, std::uint64_t end);

 private:
  // A record's place in the file.
  struct Span {
    std::uint64_t offset = 0;
    std::uint8_t opcode = 0;
    std::uint64_t length = 0;  // of the content
    std::uint64_t content_offset() const { return offset + kRecordPrefixSize; }
    std::uint64_t end() const { return content_offset() + length; }
  };

  // The one check of a record's prefix, in the file or in a chunk's records: `prefix`
  // holds what is there of the 9 bytes at `offset`; the record must end by `limit`.
  // Throws naming `where` when it is cut short or runs past `limit`.
  static Span span_at(std::string_view prefix, std::uint64_t offset, std::uint64_t limit,
                      const std::string& where);

  std::string read_bytes(std::uint64_t offset, std::uint64_t size);
  std::string where(std::string_view record, std::uint64_t offset) const;
  // The record at `offset` in the file, which must end by `limit`.
  Span record_at(std::uint64_t offset, std::uint64_t limit, std::string_view record);
  // The record at `offset` as `index` says it is (`opcode`, `length` bytes in all).
  std::string indexed_record(std::uint64_t offset, std::uint64_t length, Opcode opcode,
                             std::string_view record);
  // The chunk's records, decompressed and CRC-checked.
  std::string chunk_records(const Span& chunk);
  std::vector<Message> parse_chunk_records(const std::string& records, std::uint64_t offset);
  bool read_summary();
  void clear_indexes();
  void scan(std::string summary_problem);
  void index_record(const Span& record);
  std::optional<std::uint64_t> find_intact_chunk(std::uint64_t from);
  void add_channel(Channel channel, std::uint64_t offset);

  const std::filesystem::path file_;
  std::ifstream in_;
  std::uint64_t file_size_ = 0;
  std::string library_;
  std::uint64_t data_start_ = 0;  // after the Header
  std::optional<Recovery> recovery_;
  std::optional<DataEnd> data_end_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::vector<ChunkIndex> chunks_;
  std::vector<AttachmentIndex> attachments_;
  std::vector<MetadataIndex> metadata_;
  std::optional<Statistics> statistics_;
};

}  // namespace tilth::mcap
