// zstd level 1 and LZ4 frames at the default level. On noisy camera images zstd's gain
// is its entropy coding of literals, which level 1 already does in full: levels 2-3 cost
// 1.2-5x the time for files at most 2 % smaller, negative levels skip it (no gain at
// all), and LZ4 finds nothing to gain (docs/mcap.md, bench/mcap).
#include "mcap/compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <memory>

#include "mcap/mcap_format.h"
#include "tilth/error.h"

namespace tilth::mcap {
namespace {

constexpr int kZstdLevel = 1;

std::string zstd_compress(std::string_view bytes) {
  std::string out(ZSTD_compressBound(bytes.size()), '\0');
  const std::size_t size =
      ZSTD_compress(out.data(), out.size(), bytes.data(), bytes.size(), kZstdLevel);
  if (ZSTD_isError(size)) throw Error(std::string("zstd compression: ") + ZSTD_getErrorName(size));
  out.resize(size);
  return out;
}

std::string lz4_compress(std::string_view bytes) {
  LZ4F_preferences_t preferences{};
  preferences.frameInfo.contentSize = bytes.size();
  std::string out(LZ4F_compressFrameBound(bytes.size(), &preferences), '\0');
  const std::size_t size =
      LZ4F_compressFrame(out.data(), out.size(), bytes.data(), bytes.size(), &preferences);
  if (LZ4F_isError(size)) throw Error(std::string("lz4 compression: ") + LZ4F_getErrorName(size));
  out.resize(size);
  return out;
}

// The bytes decompression produces, kept in a buffer that grows as they come, up to one
// byte more than the chunk says it holds: a forged size allocates no more than the data
// really decompresses to, and more data than stated is seen.
class Output {
 public:
  Output(std::size_t expected, std::size_t compressed_size)
      : limit_(expected + 1),
        buffer_(std::min(limit_, std::max(kFirstAllocation, 4 * compressed_size)), '\0') {}

  // Room for the next bytes; empty once one byte past the expected size was produced.
  std::pair<char*, std::size_t> room() {
    if (used_ == buffer_.size() && buffer_.size() < limit_) {
      buffer_.resize(std::min(limit_, 2 * buffer_.size()));
    }
    return {buffer_.data() + used_, buffer_.size() - used_};
  }
  void produced(std::size_t size) { used_ += size; }
  std::size_t size() const { return used_; }
  std::string take() {
    buffer_.resize(used_);
    return std::move(buffer_);
  }

 private:
  static constexpr std::size_t kFirstAllocation = 1 << 20;
  const std::size_t limit_;
  std::string buffer_;
  std::size_t used_ = 0;
};

void check_size(const Output& out, std::size_t size, bool complete, std::string_view name,
                const std::string& where) {
  if (out.size() > size) {
    throw Error(where + ": " + std::string(name) + " data holds more than the " +
                std::to_string(size) + " bytes the chunk's uncompressed_size says");
  }
  if (!complete || out.size() != size) {
    throw Error(where + ": expected " + std::to_string(size) + " bytes after decompression (" +
                "uncompressed_size), got " + std::to_string(out.size()) +
                (complete ? "" : " in an incomplete " + std::string(name) + " frame"));
  }
}

std::string zstd_decompress(std::string_view bytes, std::size_t size, const std::string& where) {
  const std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> context(ZSTD_createDCtx(),
                                                                     &ZSTD_freeDCtx);
  if (!context) throw Error(where + ": cannot create a zstd decompression context");
  Output out(size, bytes.size());
  ZSTD_inBuffer in{bytes.data(), bytes.size(), 0};
  std::size_t hint = 1;  // 0 once a frame is complete
  for (;;) {
    const auto [room, room_size] = out.room();
    if (room_size == 0) break;
    ZSTD_outBuffer buffer{room, room_size, 0};
    hint = ZSTD_decompressStream(context.get(), &buffer, &in);
    if (ZSTD_isError(hint)) {
      throw Error(where + ": zstd data cannot be decompressed: " + ZSTD_getErrorName(hint));
    }
    out.produced(buffer.pos);
    if (in.pos == in.size && (hint == 0 || buffer.pos == 0)) break;
  }
  check_size(out, size, hint == 0 && in.pos == in.size, "zstd", where);
  return out.take();
}

std::string lz4_decompress(std::string_view bytes, std::size_t size, const std::string& where) {
  LZ4F_dctx* raw_context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw_context, LZ4F_VERSION))) {
    throw Error(where + ": cannot create an LZ4 decompression context");
  }
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> context(
      raw_context, &LZ4F_freeDecompressionContext);
  Output out(size, bytes.size());
  std::size_t read = 0;
  std::size_t hint = 1;  // 0 once the frame is complete
  while (hint != 0) {
    const auto [room, room_size] = out.room();
    if (room_size == 0) break;
    std::size_t out_size = room_size;
    std::size_t in_size = bytes.size() - read;
    hint = LZ4F_decompress(context.get(), room, &out_size, bytes.data() + read, &in_size, nullptr);
    if (LZ4F_isError(hint)) {
      throw Error(where + ": lz4 data cannot be decompressed: " + LZ4F_getErrorName(hint));
    }
    out.produced(out_size);
    read += in_size;
    if (out_size == 0 && in_size == 0) break;
  }
  check_size(out, size, hint == 0, "lz4", where);
  return out.take();
}

}  // namespace

std::string compress(std::string_view compression, std::string_view bytes) {
  if (compression == kZstd) return zstd_compress(bytes);
  if (compression == kLz4) return lz4_compress(bytes);
  return std::string(bytes);
}

std::string decompress(std::string_view compression, std::string_view bytes, std::uint64_t size,
                       const std::string& where) {
  if (size > kMaxChunkRecordsSize) {
    throw Error(where + ": uncompressed_size " + std::to_string(size) + " exceeds " +
                std::to_string(kMaxChunkRecordsSize) +
                " bytes, the most a chunk may hold (a damaged or forged size?)");
  }
  if (compression == kZstd) return zstd_decompress(bytes, size, where);
  if (compression == kLz4) return lz4_decompress(bytes, size, where);
  if (!compression.empty()) {
    throw Error(where + ": compression '" + std::string(compression) +
                "' is not supported; expected zstd, lz4 or none");
  }
  if (bytes.size() != size) {
    throw Error(where + ": expected " + std::to_string(size) + " uncompressed bytes, got " +
                std::to_string(bytes.size()));
  }
  return std::string(bytes);
}

}  // namespace tilth::mcap
