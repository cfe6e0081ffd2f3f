#include "mcap/mcap_reader.h"

#include <algorithm>

#include "mcap/compression.h"
#include "mcap/crc32.h"
#include "mcap/record_codec.h"
#include "tilth/error.h"

namespace tilth::mcap {
namespace {

// Read at a time when the file is checked or searched.
constexpr std::uint64_t kBlockSize = 1 << 20;
// A Chunk's fields before its records: three u64, the CRC, the compression name (at
// most 64 bytes here: MCAP's names are "zstd", "lz4" and "") and the records' length.
constexpr std::uint64_t kChunkHeadSize = 8 * 3 + 4 + 4 + 64 + 8;

std::string_view magic() { return {kMagic.data(), kMagic.size()}; }

bool is_known(std::uint8_t opcode) {
  return opcode >= static_cast<std::uint8_t>(Opcode::kHeader) &&
         opcode <= static_cast<std::uint8_t>(Opcode::kDataEnd);
}

// Opcodes 0x80 and above are for private records, which readers skip (MCAP spec).
bool is_private(std::uint8_t opcode) { return opcode >= 0x80; }

// A Chunk's fields up to its records, which must fill the rest of its `length` bytes.
struct ChunkHead {
  ChunkIndex index;
  std::uint32_t crc = 0;
  std::uint64_t records_start = 0;  // in the content
};

ChunkHead parse_chunk_head(std::string_view head, std::uint64_t offset, std::uint64_t length,
                           const std::string& where) {
  RecordParser parser(head, where);
  ChunkHead chunk;
  chunk.index.chunk_start_offset = offset;
  chunk.index.chunk_length = kRecordPrefixSize + length;
  chunk.index.message_start_time = parser.u64("message_start_time");
  chunk.index.message_end_time = parser.u64("message_end_time");
  chunk.index.uncompressed_size = parser.u64("uncompressed_size");
  chunk.crc = parser.u32("uncompressed_crc");
  chunk.index.compression = parser.string("compression");
  chunk.index.compressed_size = parser.u64("records length");
  chunk.records_start = parser.position();
  if (chunk.index.compressed_size != length - chunk.records_start) {
    throw Error(where + ": its records field says " + std::to_string(chunk.index.compressed_size) +
                " bytes; expected " + std::to_string(length - chunk.records_start) +
                ", the rest of the record (damaged length?)");
  }
  return chunk;
}

}  // namespace

McapReader::McapReader(std::filesystem::path file, Index index) : file_(std::move(file)) {
  std::error_code error;
  const auto status = std::filesystem::status(file_, error);
  if (error) throw Error(file_.string() + ": cannot open: " + error.message());
  if (!std::filesystem::is_regular_file(status)) {
    throw Error(file_.string() + ": not a regular file; expected an MCAP file");
  }
  in_.open(file_, std::ios::binary);
  if (!in_) throw Error(file_.string() + ": cannot open");
  file_size_ = std::filesystem::file_size(file_, error);
  if (error) throw Error(file_.string() + ": cannot read its size: " + error.message());
  if (file_size_ < kMagic.size() + kRecordPrefixSize || read_bytes(0, kMagic.size()) != magic()) {
    throw Error(file_.string() + ": not an MCAP file (expected the magic bytes \\x89MCAP0\\r\\n)");
  }
  const Span header = record_at(kMagic.size(), file_size_, "Header");
  if (header.opcode != static_cast<std::uint8_t>(Opcode::kHeader)) {
    throw Error(where("Header", kMagic.size()) + ": expected a Header record (opcode 1), found " +
                std::to_string(header.opcode));
  }
  const std::string header_bytes = read_bytes(header.content_offset(), header.length);
  RecordParser parser(header_bytes, where("Header", header.offset));
  parser.string("profile");
  library_ = parser.string("library");
  data_start_ = header.end();
  if (index == Index::kScan) {
    scan("");
    return;
  }
  try {
    if (read_summary()) return;
    scan("");
  } catch (const Error& damaged) {
    clear_indexes();
    scan(damaged.what());
  }
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

McapReader::Span McapReader::span_at(std::string_view prefix, std::uint64_t offset,
                                     std::uint64_t limit, const std::string& where) {
  if (prefix.size() < kRecordPrefixSize) {
    throw Error(where + ": cut short: expected a " + std::to_string(kRecordPrefixSize) +
                "-byte opcode and length, " + std::to_string(prefix.size()) + " bytes are left");
  }
  RecordParser parser(prefix.substr(0, kRecordPrefixSize), where);
  Span span;
  span.offset = offset;
  span.opcode = parser.u8("opcode");
  span.length = parser.u64("record length");
  const std::uint64_t room = limit - offset - kRecordPrefixSize;
  if (span.length > room) {
    throw Error(where + ": record (opcode " + std::to_string(span.opcode) + ") of " +
                std::to_string(span.length) + " bytes runs past its end: " + std::to_string(room) +
                " bytes are left (cut short, or a damaged length)");
  }
  return span;
}

McapReader::Span McapReader::record_at(std::uint64_t offset, std::uint64_t limit,
                                       std::string_view record) {
  const std::uint64_t available = offset < limit ? limit - offset : 0;
  return span_at(read_bytes(offset, std::min(available, kRecordPrefixSize)), offset, limit,
                 where(record, offset));
}

std::string McapReader::indexed_record(std::uint64_t offset, std::uint64_t length, Opcode opcode,
                                       std::string_view record) {
  const Span span = record_at(offset, file_size_, record);
  if (span.opcode != static_cast<std::uint8_t>(opcode) || span.end() - offset != length) {
    throw Error(where(record, offset) + ": expected " + std::string(record) + " record (opcode " +
                std::to_string(static_cast<int>(opcode)) + ") of " + std::to_string(length) +
                " bytes as indexed, found opcode " + std::to_string(span.opcode) + " of " +
                std::to_string(span.end() - offset) + " bytes");
  }
  return read_bytes(span.content_offset(), span.length);
}

std::uint32_t McapReader::crc_of(std::uint64_t begin, std::uint64_t end) {
  std::uint32_t crc = 0;
  for (std::uint64_t offset = begin; offset < end; offset += kBlockSize) {
    crc = crc32(read_bytes(offset, std::min(kBlockSize, end - offset)), crc);
  }
  return crc;
}

// False when the file has no Footer or the Footer points to no summary; throws when
// either is damaged.
bool McapReader::read_summary() {
  const std::uint64_t footer_size = kRecordPrefixSize + kFooterContentSize;
  if (file_size_ < data_start_ + footer_size + kMagic.size()) return false;
  if (read_bytes(file_size_ - kMagic.size(), kMagic.size()) != magic()) return false;
  const std::uint64_t footer_offset = file_size_ - kMagic.size() - footer_size;
  const Span footer = record_at(footer_offset, file_size_ - kMagic.size(), "Footer");
  if (footer.opcode != static_cast<std::uint8_t>(Opcode::kFooter) ||
      footer.length != kFooterContentSize) {
    return false;
  }
  const std::string footer_bytes = read_bytes(footer.content_offset(), footer.length);
  RecordParser parser(footer_bytes, where("Footer", footer_offset));
  const std::uint64_t summary_start = parser.u64("summary_start");
  parser.u64("summary_offset_start");
  const std::uint32_t summary_crc = parser.u32("summary_crc");
  if (summary_start == 0) return false;
  if (summary_start < data_start_ || summary_start > footer_offset) {
    throw Error(where("Footer", footer_offset) + ": summary_start " +
                std::to_string(summary_start) + " is outside the file's data");
  }
  if (summary_crc != 0) {
    const std::uint32_t computed = crc_of(summary_start, file_size_ - kMagic.size() - 4);
    if (computed != summary_crc) {
      throw Error(where("summary section", summary_start) + ": CRC mismatch (stored " +
                  std::to_string(summary_crc) + ", computed " + std::to_string(computed) + ")");
    }
  }
  for (std::uint64_t offset = summary_start; offset < footer_offset;) {
    const Span record = record_at(offset, footer_offset, "summary record");
    const std::string bytes = read_bytes(record.content_offset(), record.length);
    const RecordParser content(bytes, where("summary record", offset));
    switch (static_cast<Opcode>(record.opcode)) {
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
    offset = record.end();
  }
  std::sort(chunks_.begin(), chunks_.end(), [](const ChunkIndex& a, const ChunkIndex& b) {
    return a.chunk_start_offset < b.chunk_start_offset;
  });
  // The DataEnd record just before the summary, as writers place it.
  const std::uint64_t data_end_size = kRecordPrefixSize + 4;
  if (summary_start >= data_start_ + data_end_size) {
    const Span data_end = record_at(summary_start - data_end_size, summary_start, "DataEnd");
    if (data_end.opcode == static_cast<std::uint8_t>(Opcode::kDataEnd) && data_end.length == 4) {
      data_end_ = DataEnd{
          data_end.offset,
          RecordParser(read_bytes(data_end.content_offset(), 4), "").u32("data_section_crc")};
    }
  }
  return true;
}

void McapReader::clear_indexes() {
  schemas_.clear();
  channels_.clear();
  chunks_.clear();
  attachments_.clear();
  metadata_.clear();
  statistics_.reset();
  data_end_.reset();
}

void McapReader::add_channel(Channel channel, std::uint64_t offset) {
  if (channel.schema_id != 0 && !schemas_.contains(channel.schema_id)) {
    throw Error(where("Channel", offset) + ": channel '" + channel.topic + "' names schema " +
                std::to_string(channel.schema_id) + ", which comes nowhere before it");
  }
  channels_[channel.id] = std::move(channel);
}

// Reads records from the Header on up to the DataEnd record. A record that is damaged
// (cut short, an impossible length, an unknown opcode, a field that runs past it) is
// skipped up to the next chunk whose CRC matches; with none, the scan stops there.
void McapReader::scan(std::string summary_problem) {
  Recovery recovery;
  recovery.summary_problem = std::move(summary_problem);
  std::uint64_t offset = data_start_;
  recovery.stop_reason = "the file ends after a complete record";
  while (offset < file_size_) {
    try {
      const Span record = record_at(offset, file_size_, "record");
      if (record.opcode == static_cast<std::uint8_t>(Opcode::kDataEnd) ||
          record.opcode == static_cast<std::uint8_t>(Opcode::kFooter)) {
        if (record.opcode == static_cast<std::uint8_t>(Opcode::kDataEnd)) {
          const std::string bytes = read_bytes(record.content_offset(), record.length);
          RecordParser content(bytes, where("DataEnd", offset));
          data_end_ = DataEnd{offset, content.u32("data_section_crc")};
        }
        recovery.stop_reason =
            "the data section ends at offset " + std::to_string(offset) +
            (recovery.summary_problem.empty() ? " but the summary is missing" : "");
        break;
      }
      index_record(record);
      offset = record.end();
    } catch (const Error& damaged) {
      const std::optional<std::uint64_t> next = find_intact_chunk(offset + 1);
      const std::uint64_t end = next.value_or(file_size_);
      recovery.skipped.push_back({offset, end - offset, damaged.what()});
      if (!next) {
        recovery.stop_reason = damaged.what();
        break;
      }
      offset = end;
    }
  }
  recovery.readable_bytes = offset;
  recovery_ = std::move(recovery);
}

void McapReader::index_record(const Span& record) {
  const std::uint64_t offset = record.offset;
  if (!is_known(record.opcode)) {
    if (is_private(record.opcode)) return;
    throw Error(where("record", offset) + ": unknown opcode " + std::to_string(record.opcode) +
                " (zeroed or damaged data?)");
  }
  switch (static_cast<Opcode>(record.opcode)) {
    case Opcode::kSchema: {
      const std::string bytes = read_bytes(record.content_offset(), record.length);
      Schema schema = decode_schema(RecordParser(bytes, where("Schema", offset)));
      schemas_[schema.id] = std::move(schema);
      break;
    }
    case Opcode::kChannel: {
      const std::string bytes = read_bytes(record.content_offset(), record.length);
      add_channel(decode_channel(RecordParser(bytes, where("Channel", offset))), offset);
      break;
    }
    case Opcode::kAttachment: {
      const std::string bytes = read_bytes(record.content_offset(), record.length);
      const Attachment attachment =
          decode_attachment(RecordParser(bytes, where("Attachment", offset)));
      attachments_.push_back({offset, kRecordPrefixSize + record.length, attachment.log_time,
                              attachment.create_time, attachment.data.size(), attachment.name,
                              attachment.media_type});
      break;
    }
    case Opcode::kMetadata: {
      const std::string bytes = read_bytes(record.content_offset(), record.length);
      const Metadata metadata = decode_metadata(RecordParser(bytes, where("Metadata", offset)));
      metadata_.push_back({offset, kRecordPrefixSize + record.length, metadata.name});
      break;
    }
    case Opcode::kChunk: {
      // The fields before the records; the records are read when played.
      const std::string head =
          read_bytes(record.content_offset(), std::min(record.length, kChunkHeadSize));
      chunks_.push_back(
          parse_chunk_head(head, offset, record.length, where("Chunk", offset)).index);
      break;
    }
    case Opcode::kMessageIndex:
      if (!chunks_.empty()) {
        ChunkIndex& chunk = chunks_.back();
        const std::string bytes =
            read_bytes(record.content_offset(), std::min<std::uint64_t>(record.length, 2));
        chunk.message_index_offsets[RecordParser(bytes, where("MessageIndex", offset))
                                        .u16("channel_id")] = offset;
        chunk.message_index_length += kRecordPrefixSize + record.length;
      }
      break;
    default:  // messages outside chunks: Tilth writes none
      break;
  }
}

// The offset of the first chunk at or after `from` whose records decompress, match
// their CRC and parse: where a scan resumes after damage.
std::optional<std::uint64_t> McapReader::find_intact_chunk(std::uint64_t from) {
  const char chunk_opcode = static_cast<char>(Opcode::kChunk);
  for (std::uint64_t block = from; block < file_size_; block += kBlockSize) {
    const std::string bytes = read_bytes(block, std::min(kBlockSize, file_size_ - block));
    for (std::size_t i = bytes.find(chunk_opcode); i != std::string::npos;
         i = bytes.find(chunk_opcode, i + 1)) {
      try {
        const Span chunk = record_at(block + i, file_size_, "Chunk");
        parse_chunk_records(chunk_records(chunk), chunk.offset);
        return chunk.offset;
      } catch (const Error&) {
        // not a chunk, or a damaged one: search on
      }
    }
  }
  return std::nullopt;
}

std::string McapReader::chunk_records(const Span& chunk) {
  const std::string place = where("Chunk", chunk.offset);
  const std::string head =
      read_bytes(chunk.content_offset(), std::min(chunk.length, kChunkHeadSize));
  const ChunkHead parsed = parse_chunk_head(head, chunk.offset, chunk.length, place);
  const std::string compressed =
      read_bytes(chunk.content_offset() + parsed.records_start, parsed.index.compressed_size);
  std::string records =
      decompress(parsed.index.compression, compressed, parsed.index.uncompressed_size, place);
  if (parsed.crc != 0) {
    const std::uint32_t computed = crc32(records);
    if (computed != parsed.crc) {
      throw Error(place + ": CRC mismatch (stored " + std::to_string(parsed.crc) + ", computed " +
                  std::to_string(computed) + "): the chunk is corrupt");
    }
  }
  return records;
}

std::vector<Message> McapReader::parse_chunk_records(const std::string& records,
                                                     std::uint64_t offset) {
  const std::string place = where("Chunk", offset);
  std::vector<Message> messages;
  for (std::uint64_t position = 0; position < records.size();) {
    const Span record = span_at(
        std::string_view(records).substr(position, kRecordPrefixSize), position, records.size(),
        place + ": record inside the chunk at byte " + std::to_string(position));
    const RecordParser content(
        std::string_view(records).substr(record.content_offset(), record.length), place);
    switch (static_cast<Opcode>(record.opcode)) {
      case Opcode::kMessage:
        messages.push_back(decode_message(content));
        break;
      case Opcode::kSchema: {
        Schema schema = decode_schema(content);
        schemas_[schema.id] = std::move(schema);
        break;
      }
      case Opcode::kChannel:
        add_channel(decode_channel(content), offset);
        break;
      default:
        break;
    }
    position = record.end();
  }
  return messages;
}

std::vector<Message> McapReader::read_chunk(const ChunkIndex& chunk) {
  const Span span = record_at(chunk.chunk_start_offset, file_size_, "Chunk");
  if (span.opcode != static_cast<std::uint8_t>(Opcode::kChunk) ||
      span.end() - span.offset != chunk.chunk_length) {
    throw Error(where("Chunk", span.offset) + ": expected a Chunk record (opcode 6) of " +
                std::to_string(chunk.chunk_length) + " bytes as indexed, found opcode " +
                std::to_string(span.opcode) + " of " + std::to_string(span.end() - span.offset) +
                " bytes");
  }
  return parse_chunk_records(chunk_records(span), span.offset);
}

Attachment McapReader::read_attachment(const AttachmentIndex& index) {
  const std::string content =
      indexed_record(index.offset, index.length, Opcode::kAttachment, "Attachment");
  return decode_attachment(RecordParser(content, where("Attachment", index.offset)));
}

Metadata McapReader::read_metadata(const MetadataIndex& index) {
  const std::string content =
      indexed_record(index.offset, index.length, Opcode::kMetadata, "Metadata");
  return decode_metadata(RecordParser(content, where("Metadata", index.offset)));
}

std::optional<Attachment> McapReader::find_attachment(std::string_view name) {
  for (const AttachmentIndex& index : attachments_) {
    if (index.name == name) return read_attachment(index);
  }
  return std::nullopt;
}

}  // namespace tilth::mcap
