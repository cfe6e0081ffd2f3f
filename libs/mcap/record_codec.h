// Encoding and decoding of MCAP record fields: little-endian integers, strings and byte
// arrays with their length prefixes, and maps. Decoding is bounds-checked and names the
// field that runs past its record.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "mcap/mcap_format.h"

namespace tilth::mcap {

// Builds one record's content, then the whole record with its prefix.
class RecordBuilder {
 public:
  RecordBuilder& u8(std::uint8_t value);
  RecordBuilder& u16(std::uint16_t value);
  RecordBuilder& u32(std::uint32_t value);
  RecordBuilder& u64(std::uint64_t value);
  RecordBuilder& string(std::string_view value);   // u32 length + bytes
  RecordBuilder& bytes32(std::string_view value);  // u32 length + bytes
  RecordBuilder& bytes64(std::string_view value);  // u64 length + bytes
  RecordBuilder& raw(std::string_view value);      // no prefix
  RecordBuilder& string_map(const std::map<std::string, std::string>& values);
  RecordBuilder& u16_u64_map(const std::map<std::uint16_t, std::uint64_t>& values);

  const std::string& content() const { return content_; }
  // Opcode, content length and content.
  std::string record(Opcode opcode) const;

 private:
  std::string content_;
};

// Reads one record's content front to back.
class RecordParser {
 public:
  // `where` names the record in errors ("Chunk at offset 1234").
  RecordParser(std::string_view content, std::string where)
      : content_(content), where_(std::move(where)) {}

  std::uint8_t u8(std::string_view field);
  std::uint16_t u16(std::string_view field);
  std::uint32_t u32(std::string_view field);
  std::uint64_t u64(std::string_view field);
  std::string string(std::string_view field);
  std::string_view bytes32(std::string_view field);
  std::string_view bytes64(std::string_view field);
  std::map<std::string, std::string> string_map(std::string_view field);
  std::map<std::uint16_t, std::uint64_t> u16_u64_map(std::string_view field);
  // The content not read yet.
  std::string_view rest() const { return content_.substr(position_); }
  // The content read so far.
  std::string_view consumed() const { return content_.substr(0, position_); }
  const std::string& where() const { return where_; }
  std::size_t position() const { return position_; }

 private:
  std::string_view take(std::uint64_t size, std::string_view field);

  std::string_view content_;
  std::string where_;
  std::size_t position_ = 0;
};

std::string encode(const Schema& schema);
std::string encode(const Channel& channel);
std::string encode(const Message& message);
std::string encode(const ChunkIndex& index);
std::string encode(const Attachment& attachment);  // with the CRC of its content
std::string encode(const AttachmentIndex& index);
std::string encode(const Metadata& metadata);
std::string encode(const MetadataIndex& index);
std::string encode(const Statistics& statistics);

Schema decode_schema(RecordParser parser);
Channel decode_channel(RecordParser parser);
Message decode_message(RecordParser parser);
ChunkIndex decode_chunk_index(RecordParser parser);
// Throws when the stored CRC (if not 0) does not match.
Attachment decode_attachment(RecordParser parser);
AttachmentIndex decode_attachment_index(RecordParser parser);
Metadata decode_metadata(RecordParser parser);
MetadataIndex decode_metadata_index(RecordParser parser);
Statistics decode_statistics(RecordParser parser);

}  // namespace tilth::mcap
