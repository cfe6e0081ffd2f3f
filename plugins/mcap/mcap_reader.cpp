#include "mcap_reader.h"

#include <algorithm>

#include "compression.h"
#include "crc32.h"
#include "record_codec.h"
#include "tilth/error.h"

namespace tilth::mcap {
namespace {

std::string_view magic() { return {kMagic.data(), kMagic.size()}; }

// Opcode and content length at the start of `bytes` (at least kRecordPrefixSize long).
std::pair<std::uint8_t, std::uint64_t> parse_prefix(std::string_view bytes,
                                                    const std::string& where) {
  RecordParser parser(bytes.substr(0, kRecordPrefixSize), where);
  const std::uint8_t opcode = parser.u8("opcode");
  return {opcode, parser.u64("record length")};
}

bool is_known(std::uint8_t opcode) {
  return opcode >= static_cast<std::uint8_t>(Opcode::kHeader) &&
         opcode <= static_cast<std::uint8_t>(Opcode::kDataEnd);
}

}  // namespace

McapReader::McapReader(std::filesystem::path file) : file_(std::move(file)) {
  in_.open(file_, std::ios::binary);
  if (!in_) throw Error(file_.string() + ": cannot open");
  std::error_code error;
  file_size_ = std::filesystem::file_size(file_, error);
  if (error) throw Error(file_.string() + ": cannot read its size: " + error.message());
  if (file_size_ < kMagic.size() + kRecordPrefixSize || read_bytes(0, kMagic.size()) != magic()) {
    throw Error(file_.string() + ": not an MCAP file (expected the magic bytes \\x89MCAP0\\r\\n)");
  }
  const std::string prefix = read_bytes(kMagic.size(), kRecordPrefixSize);
  const auto [opcode, length] = parse_prefix(prefix, where("Header", kMagic.size()));
  if (opcode != static_cast<std::uint8_t>(Opcode::kHeader) ||
      length > file_size_ - kMagic.size() - kRecordPrefixSize) {
    throw Error(where("Header", kMagic.size()) + ": expected a complete Header record");
  }
  const std::string header_bytes = read_bytes(kMagic.size() + kRecordPrefixSize, length);
  RecordParser header(header_bytes, where("Header", kMagic.size()));
  header.string("profile");
  library_ = header.string("library");
  data_start_ = kMagic.size() + kRecordPrefixSize + length;
  if (!read_summary()) scan();
}

std::string McapReader::where(std::string_view record, std::uint64_t offset) const {
  return file_.string() + ": " + std::string(record) + " at offset " + std::to_string(offset);
}

std::string McapReader::read_bytes(std::uint64_t offset, std::uint64_t size) {
  if (offset > file_size_ || size > file_size_ - offset) {
    throw Error(file_.string() + ": expected " + std::to_string(size) + " bytes at offset " +
                std::to_string(offset) + ", the file has " + std::to_string(file_size_));
  }
  std::string bytes(size, '\0');
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(offset));
  in_.read(bytes.data(), static_cast<std::streamsize>(size));
  if (!in_) throw Error(file_.string() + ": cannot read at offset " + std::to_string(offset));
  return bytes;
}

// False when the file has no Footer or the Footer points to no summary.
bool McapReader::read_summary() {
  const std::uint64_t footer_size = kRecordPrefixSize + kFooterContentSize;
  if (file_size_ < data_start_ + footer_size + kMagic.size()) return false;
  if (read_bytes(file_size_ - kMagic.size(), kMagic.size()) != magic()) return false;
  const std::uint64_t footer_offset = file_size_ - kMagic.size() - footer_size;
  const std::string footer_bytes = read_bytes(footer_offset, footer_size);
  const auto [opcode, length] = parse_prefix(footer_bytes, where("Footer", footer_offset));
  if (opcode != static_cast<std::uint8_t>(Opcode::kFooter) || length != kFooterContentSize) {
    return false;
  }
  RecordParser footer(std::string_view(footer_bytes).substr(kRecordPrefixSize),
                      where("Footer", footer_offset));
  const std::uint64_t summary_start = footer.u64("summary_start");
  footer.u64("summary_offset_start");
  const std::uint32_t summary_crc = footer.u32("summary_crc");
  if (summary_start == 0) return false;
  if (summary_start < data_start_ || summary_start > footer_offset) {
    throw Error(where("Footer", footer_offset) + ": summary_start " +
                std::to_string(summary_start) + " is outside the file's data");
  }

  const std::string summary = read_bytes(summary_start, footer_offset - summary_start);
  if (summary_crc != 0) {
    const std::string_view footer_fields =
        std::string_view(footer_bytes).substr(0, footer_size - 4);
    const std::uint32_t computed = crc32(footer_fields, crc32(summary));
    if (computed != summary_crc) {
      throw Error(where("summary section", summary_start) + ": CRC mismatch (stored " +
                  std::to_string(summary_crc) + ", computed " + std::to_string(computed) + ")");
    }
  }
  std::uint64_t position = 0;
  while (position < summary.size()) {
    const std::uint64_t offset = summary_start + position;
    if (summary.size() - position < kRecordPrefixSize) {
      throw Error(where("summary record", offset) + ": cut short");
    }
    const auto [record_opcode, record_length] =
        parse_prefix(std::string_view(summary).substr(position), where("summary record", offset));
    if (record_length > summary.size() - position - kRecordPrefixSize) {
      throw Error(where("summary record", offset) + ": runs past the summary section");
    }
    const RecordParser content(
        std::string_view(summary).substr(position + kRecordPrefixSize, record_length),
        where("summary record", offset));
    switch (static_cast<Opcode>(record_opcode)) {
      case Opcode::kSchema: {
        Schema schema = decode_schema(content);
        schemas_[schema.id] = std::move(schema);
        break;
      }
      case Opcode::kChannel:
        add_channel(decode_channel(content), offset);
        break;
      case Opcode::kChunkIndex:
        chunks_.push_back(decode_chunk_index(content));
        break;
      case Opcode::kAttachmentIndex:
        attachments_.push_back(decode_attachment_index(content));
        break;
      case Opcode::kMetadataIndex:
        metadata_.push_back(decode_metadata_index(content));
        break;
      case Opcode::kStatistics:
        statistics_ = decode_statistics(content);
        break;
      default:  // SummaryOffset and records a later minor version may add
        break;
    }
    position += kRecordPrefixSize + record_length;
  }
  std::sort(chunks_.begin(), chunks_.end(), [](const ChunkIndex& a, const ChunkIndex& b) {
    return a.chunk_start_offset < b.chunk_start_offset;
  });
  return true;
}

void McapReader::add_channel(Channel channel, std::uint64_t offset) {
  if (channel.schema_id != 0 && !schemas_.contains(channel.schema_id)) {
    throw Error(where("Channel", offset) + ": channel '" + channel.topic + "' names schema " +
                std::to_string(channel.schema_id) + ", which comes nowhere before it");
  }
  channels_[channel.id] = std::move(channel);
}

// Reads records from the Header on; keeps what is complete and stops at the first
// record that is cut short, unknown or the end of the data section.
void McapReader::scan() {
  Recovery recovery;
  std::uint64_t offset = data_start_;
  for (;;) {
    recovery.readable_bytes = offset;
    if (file_size_ - offset < kRecordPrefixSize) {
      recovery.stop_reason = file_size_ == offset
                                 ? "the file ends after a complete record"
                                 : "a record is cut short at offset " + std::to_string(offset);
      break;
    }
    const auto [opcode, length] =
        parse_prefix(read_bytes(offset, kRecordPrefixSize), where("record", offset));
    if (!is_known(opcode)) {
      recovery.stop_reason = "unknown record opcode " + std::to_string(opcode) + " at offset " +
                             std::to_string(offset) + " (zeroed or damaged data?)";
      break;
    }
    if (length > file_size_ - offset - kRecordPrefixSize) {
      recovery.stop_reason = "a record (opcode " + std::to_string(opcode) + ") at offset " +
                             std::to_string(offset) + " is cut short: it needs " +
                             std::to_string(length) + " bytes, the file has " +
                             std::to_string(file_size_ - offset - kRecordPrefixSize);
      break;
    }
    const std::uint64_t content_offset = offset + kRecordPrefixSize;
    const Opcode record = static_cast<Opcode>(opcode);
    if (record == Opcode::kDataEnd || record == Opcode::kFooter) {
      recovery.readable_bytes = offset;
      recovery.stop_reason = "the data section ends at offset " + std::to_string(offset) +
                             " but the summary is missing";
      break;
    }
    switch (record) {
      case Opcode::kSchema: {
        const std::string bytes = read_bytes(content_offset, length);
        Schema schema = decode_schema(RecordParser(bytes, where("Schema", offset)));
        schemas_[schema.id] = std::move(schema);
        break;
      }
      case Opcode::kChannel: {
        const std::string bytes = read_bytes(content_offset, length);
        add_channel(decode_channel(RecordParser(bytes, where("Channel", offset))), offset);
        break;
      }
      case Opcode::kAttachment: {
        const std::string bytes = read_bytes(content_offset, length);
        const Attachment attachment =
            decode_attachment(RecordParser(bytes, where("Attachment", offset)));
        attachments_.push_back({offset, kRecordPrefixSize + length, attachment.log_time,
                                attachment.create_time, attachment.data.size(), attachment.name,
                                attachment.media_type});
        break;
      }
      case Opcode::kMetadata: {
        const std::string bytes = read_bytes(content_offset, length);
        const Metadata metadata = decode_metadata(RecordParser(bytes, where("Metadata", offset)));
        metadata_.push_back({offset, kRecordPrefixSize + length, metadata.name});
        break;
      }
      case Opcode::kChunk: {
        // The fixed fields and the compression name; the records are read when played.
        const std::uint64_t head_size = std::min<std::uint64_t>(length, 8 * 3 + 4 + 4 + 64);
        const std::string head = read_bytes(content_offset, head_size);
        RecordParser parser(head, where("Chunk", offset));
        ChunkIndex chunk;
        chunk.chunk_start_offset = offset;
        chunk.chunk_length = kRecordPrefixSize + length;
        chunk.message_start_time = parser.u64("message_start_time");
        chunk.message_end_time = parser.u64("message_end_time");
        chunk.uncompressed_size = parser.u64("uncompressed_size");
        parser.u32("uncompressed_crc");
        chunk.compression = parser.string("compression");
        chunk.compressed_size = length - parser.position() - 8;
        chunks_.push_back(std::move(chunk));
        break;
      }
      case Opcode::kMessageIndex:
        if (!chunks_.empty()) {
          ChunkIndex& chunk = chunks_.back();
          const std::string bytes = read_bytes(content_offset, std::min<std::uint64_t>(length, 2));
          chunk.message_index_offsets[RecordParser(bytes, where("MessageIndex", offset))
                                          .u16("channel_id")] = offset;
          chunk.message_index_length += kRecordPrefixSize + length;
        }
        break;
      default:  // messages outside chunks: Tilth writes none
        break;
    }
    offset = content_offset + length;
  }
  recovery_ = std::move(recovery);
}

std::vector<Message> McapReader::read_chunk(const ChunkIndex& chunk) {
  const std::string place = where("Chunk", chunk.chunk_start_offset);
  if (chunk.chunk_length < kRecordPrefixSize) throw Error(place + ": record too short");
  const std::string bytes = read_bytes(chunk.chunk_start_offset, chunk.chunk_length);
  const auto [opcode, length] = parse_prefix(bytes, place);
  if (opcode != static_cast<std::uint8_t>(Opcode::kChunk) ||
      length != chunk.chunk_length - kRecordPrefixSize) {
    throw Error(place + ": expected a Chunk record of " + std::to_string(chunk.chunk_length) +
                " bytes (as indexed), found opcode " + std::to_string(opcode));
  }
  RecordParser parser(std::string_view(bytes).substr(kRecordPrefixSize), place);
  parser.u64("message_start_time");
  parser.u64("message_end_time");
  const std::uint64_t uncompressed_size = parser.u64("uncompressed_size");
  const std::uint32_t stored_crc = parser.u32("uncompressed_crc");
  const std::string compression = parser.string("compression");
  const std::string_view compressed = parser.bytes64("records");
  const std::string records = decompress(compression, compressed, uncompressed_size, place);
  if (stored_crc != 0) {
    const std::uint32_t computed = crc32(records);
    if (computed != stored_crc) {
      throw Error(place + ": CRC mismatch (stored " + std::to_string(stored_crc) + ", computed " +
                  std::to_string(computed) + "): the chunk is corrupt");
    }
  }

  std::vector<Message> messages;
  std::uint64_t position = 0;
  while (position < records.size()) {
    if (records.size() - position < kRecordPrefixSize) {
      throw Error(place + ": a record inside the chunk is cut short at byte " +
                  std::to_string(position));
    }
    const auto [record_opcode, record_length] =
        parse_prefix(std::string_view(records).substr(position), place);
    if (record_length > records.size() - position - kRecordPrefixSize) {
      throw Error(place + ": a record inside the chunk at byte " + std::to_string(position) +
                  " runs past the chunk");
    }
    const RecordParser content(
        std::string_view(records).substr(position + kRecordPrefixSize, record_length), place);
    switch (static_cast<Opcode>(record_opcode)) {
      case Opcode::kMessage:
        messages.push_back(decode_message(content));
        break;
      case Opcode::kSchema: {
        Schema schema = decode_schema(content);
        schemas_[schema.id] = std::move(schema);
        break;
      }
      case Opcode::kChannel:
        add_channel(decode_channel(content), chunk.chunk_start_offset);
        break;
      default:
        break;
    }
    position += kRecordPrefixSize + record_length;
  }
  return messages;
}

Attachment McapReader::read_attachment(const AttachmentIndex& index) {
  const std::string place = where("Attachment", index.offset);
  const std::string bytes = read_bytes(index.offset, index.length);
  if (bytes.size() < kRecordPrefixSize) throw Error(place + ": record too short");
  const auto [opcode, length] = parse_prefix(bytes, place);
  if (opcode != static_cast<std::uint8_t>(Opcode::kAttachment) ||
      length != index.length - kRecordPrefixSize) {
    throw Error(place + ": expected an Attachment record as indexed");
  }
  return decode_attachment(RecordParser(std::string_view(bytes).substr(kRecordPrefixSize), place));
}

Metadata McapReader::read_metadata(const MetadataIndex& index) {
  const std::string place = where("Metadata", index.offset);
  const std::string bytes = read_bytes(index.offset, index.length);
  if (bytes.size() < kRecordPrefixSize) throw Error(place + ": record too short");
  const auto [opcode, length] = parse_prefix(bytes, place);
  if (opcode != static_cast<std::uint8_t>(Opcode::kMetadata) ||
      length != index.length - kRecordPrefixSize) {
    throw Error(place + ": expected a Metadata record as indexed");
  }
  return decode_metadata(RecordParser(std::string_view(bytes).substr(kRecordPrefixSize), place));
}

std::optional<Attachment> McapReader::find_attachment(std::string_view name) {
  for (const AttachmentIndex& index : attachments_) {
    if (index.name == name) return read_attachment(index);
  }
  return std::nullopt;
}

}  // namespace tilth::mcap
