#include "mcap/record_codec.h"

#include <bit>
#include <cstring>

#include "mcap/crc32.h"
#include "tilth/error.h"

namespace tilth::mcap {
namespace {

static_assert(std::endian::native == std::endian::little, "MCAP integers are little-endian");

template <class T>
void append(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

template <class T>
T load(std::string_view bytes) {
  T value;
  std::memcpy(&value, bytes.data(), sizeof(T));
  return value;
}

}  // namespace

RecordBuilder& RecordBuilder::u8(std::uint8_t value) {
  append(content_, value);
  return *this;
}
RecordBuilder& RecordBuilder::u16(std::uint16_t value) {
  append(content_, value);
  return *this;
}
RecordBuilder& RecordBuilder::u32(std::uint32_t value) {
  append(content_, value);
  return *this;
}
RecordBuilder& RecordBuilder::u64(std::uint64_t value) {
  append(content_, value);
  return *this;
}
RecordBuilder& RecordBuilder::string(std::string_view value) { return bytes32(value); }
RecordBuilder& RecordBuilder::bytes32(std::string_view value) {
  u32(static_cast<std::uint32_t>(value.size()));
  return raw(value);
}
RecordBuilder& RecordBuilder::bytes64(std::string_view value) {
  u64(value.size());
  return raw(value);
}
RecordBuilder& RecordBuilder::raw(std::string_view value) {
  content_.append(value);
  return *this;
}
RecordBuilder& RecordBuilder::string_map(const std::map<std::string, std::string>& values) {
  RecordBuilder entries;
  for (const auto& [key, value] : values) entries.string(key).string(value);
  return bytes32(entries.content());
}
RecordBuilder& RecordBuilder::u16_u64_map(const std::map<std::uint16_t, std::uint64_t>& values) {
  RecordBuilder entries;
  for (const auto& [key, value] : values) entries.u16(key).u64(value);
  return bytes32(entries.content());
}

std::string RecordBuilder::record(Opcode opcode) const {
  std::string out;
  out.reserve(kRecordPrefixSize + content_.size());
  append(out, static_cast<std::uint8_t>(opcode));
  append(out, static_cast<std::uint64_t>(content_.size()));
  out.append(content_);
  return out;
}

std::string_view RecordParser::take(std::uint64_t size, std::string_view field) {
  if (size > content_.size() - position_) {
    throw Error(where_ + ": field " + std::string(field) + " needs " + std::to_string(size) +
                " bytes at content byte " + std::to_string(position_) + ", the record has " +
                std::to_string(content_.size() - position_) + " left");
  }
  const std::string_view bytes = content_.substr(position_, size);
  position_ += size;
  return bytes;
}

std::uint8_t RecordParser::u8(std::string_view field) { return load<std::uint8_t>(take(1, field)); }
std::uint16_t RecordParser::u16(std::string_view field) {
  return load<std::uint16_t>(take(2, field));
}
std::uint32_t RecordParser::u32(std::string_view field) {
  return load<std::uint32_t>(take(4, field));
}
std::uint64_t RecordParser::u64(std::string_view field) {
  return load<std::uint64_t>(take(8, field));
}
std::string RecordParser::string(std::string_view field) { return std::string(bytes32(field)); }
std::string_view RecordParser::bytes32(std::string_view field) {
  const std::uint32_t size = u32(field);
  return take(size, field);
}
std::string_view RecordParser::bytes64(std::string_view field) {
  const std::uint64_t size = u64(field);
  return take(size, field);
}

std::map<std::string, std::string> RecordParser::string_map(std::string_view field) {
  RecordParser entries(bytes32(field), where_);
  std::map<std::string, std::string> values;
  while (!entries.rest().empty()) {
    std::string key = entries.string(field);
    values[std::move(key)] = entries.string(field);
  }
  return values;
}

std::map<std::uint16_t, std::uint64_t> RecordParser::u16_u64_map(std::string_view field) {
  RecordParser entries(bytes32(field), where_);
  std::map<std::uint16_t, std::uint64_t> values;
  while (!entries.rest().empty()) {
    const std::uint16_t key = entries.u16(field);
    values[key] = entries.u64(field);
  }
  return values;
}

std::string encode(const Schema& schema) {
  return RecordBuilder()
      .u16(schema.id)
      .string(schema.name)
      .string(schema.encoding)
      .bytes32(schema.data)
      .record(Opcode::kSchema);
}

std::string encode(const Channel& channel) {
  return RecordBuilder()
      .u16(channel.id)
      .u16(channel.schema_id)
      .string(channel.topic)
      .string(channel.message_encoding)
      .string_map(channel.metadata)
      .record(Opcode::kChannel);
}

std::string encode(const Message& message) {
  return RecordBuilder()
      .u16(message.channel_id)
      .u32(message.sequence)
      .u64(message.log_time)
      .u64(message.publish_time)
      .raw(message.data)
      .record(Opcode::kMessage);
}

std::string encode(const ChunkIndex& index) {
  return RecordBuilder()
      .u64(index.message_start_time)
      .u64(index.message_end_time)
      .u64(index.chunk_start_offset)
      .u64(index.chunk_length)
      .u16_u64_map(index.message_index_offsets)
      .u64(index.message_index_length)
      .string(index.compression)
      .u64(index.compressed_size)
      .u64(index.uncompressed_size)
      .record(Opcode::kChunkIndex);
}

std::string encode(const Attachment& attachment) {
  RecordBuilder builder;
  builder.u64(attachment.log_time)
      .u64(attachment.create_time)
      .string(attachment.name)
      .string(attachment.media_type)
      .bytes64(attachment.data);
  builder.u32(crc32(builder.content()));
  return builder.record(Opcode::kAttachment);
}

std::string encode(const AttachmentIndex& index) {
  return RecordBuilder()
      .u64(index.offset)
      .u64(index.length)
      .u64(index.log_time)
      .u64(index.create_time)
      .u64(index.data_size)
      .string(index.name)
      .string(index.media_type)
      .record(Opcode::kAttachmentIndex);
}

std::string encode(const Metadata& metadata) {
  return RecordBuilder()
      .string(metadata.name)
      .string_map(metadata.values)
      .record(Opcode::kMetadata);
}

std::string encode(const MetadataIndex& index) {
  return RecordBuilder()
      .u64(index.offset)
      .u64(index.length)
      .string(index.name)
      .record(Opcode::kMetadataIndex);
}

std::string encode(const Statistics& statistics) {
  return RecordBuilder()
      .u64(statistics.message_count)
      .u16(statistics.schema_count)
      .u32(statistics.channel_count)
      .u32(statistics.attachment_count)
      .u32(statistics.metadata_count)
      .u32(statistics.chunk_count)
      .u64(statistics.message_start_time)
      .u64(statistics.message_end_time)
      .u16_u64_map(statistics.channel_message_counts)
      .record(Opcode::kStatistics);
}

Schema decode_schema(RecordParser parser) {
  Schema schema;
  schema.id = parser.u16("id");
  schema.name = parser.string("name");
  schema.encoding = parser.string("encoding");
  schema.data = std::string(parser.bytes32("data"));
  return schema;
}

Channel decode_channel(RecordParser parser) {
  Channel channel;
  channel.id = parser.u16("id");
  channel.schema_id = parser.u16("schema_id");
  channel.topic = parser.string("topic");
  channel.message_encoding = parser.string("message_encoding");
  channel.metadata = parser.string_map("metadata");
  return channel;
}

Message decode_message(RecordParser parser) {
  Message message;
  message.channel_id = parser.u16("channel_id");
  message.sequence = parser.u32("sequence");
  message.log_time = parser.u64("log_time");
  message.publish_time = parser.u64("publish_time");
  message.data = std::string(parser.rest());
  return message;
}

ChunkIndex decode_chunk_index(RecordParser parser) {
  ChunkIndex index;
  index.message_start_time = parser.u64("message_start_time");
  index.message_end_time = parser.u64("message_end_time");
  index.chunk_start_offset = parser.u64("chunk_start_offset");
  index.chunk_length = parser.u64("chunk_length");
  index.message_index_offsets = parser.u16_u64_map("message_index_offsets");
  index.message_index_length = parser.u64("message_index_length");
  index.compression = parser.string("compression");
  index.compressed_size = parser.u64("compressed_size");
  index.uncompressed_size = parser.u64("uncompressed_size");
  return index;
}

Attachment decode_attachment(RecordParser parser) {
  Attachment attachment;
  attachment.log_time = parser.u64("log_time");
  attachment.create_time = parser.u64("create_time");
  attachment.name = parser.string("name");
  attachment.media_type = parser.string("media_type");
  attachment.data = std::string(parser.bytes64("data"));
  const std::uint32_t computed = crc32(parser.consumed());
  const std::uint32_t stored = parser.u32("crc");
  if (stored != 0 && stored != computed) {
    throw Error(parser.where() + ": attachment '" + attachment.name + "' CRC mismatch (stored " +
                std::to_string(stored) + ", computed " + std::to_string(computed) + ")");
  }
  return attachment;
}

AttachmentIndex decode_attachment_index(RecordParser parser) {
  AttachmentIndex index;
  index.offset = parser.u64("offset");
  index.length = parser.u64("length");
  index.log_time = parser.u64("log_time");
  index.create_time = parser.u64("create_time");
  index.data_size = parser.u64("data_size");
  index.name = parser.string("name");
  index.media_type = parser.string("media_type");
  return index;
}

Metadata decode_metadata(RecordParser parser) {
  Metadata metadata;
  metadata.name = parser.string("name");
  metadata.values = parser.string_map("metadata");
  return metadata;
}

MetadataIndex decode_metadata_index(RecordParser parser) {
  MetadataIndex index;
  index.offset = parser.u64("offset");
  index.length = parser.u64("length");
  index.name = parser.string("name");
  return index;
}

Statistics decode_statistics(RecordParser parser) {
  Statistics statistics;
  statistics.message_count = parser.u64("message_count");
  statistics.schema_count = parser.u16("schema_count");
  statistics.channel_count = parser.u32("channel_count");
  statistics.attachment_count = parser.u32("attachment_count");
  statistics.metadata_count = parser.u32("metadata_count");
  statistics.chunk_count = parser.u32("chunk_count");
  statistics.message_start_time = parser.u64("message_start_time");
  statistics.message_end_time = parser.u64("message_end_time");
  statistics.channel_message_counts = parser.u16_u64_map("channel_message_counts");
  return statistics;
}

}  // namespace tilth::mcap
