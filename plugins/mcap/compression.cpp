// zstd level 1 and LZ4 frames at the default level. On noisy camera images zstd's gain
// is its entropy coding of literals, which level 1 already does in full: levels 2-3 cost
// 1.2-5x the time for files at most 2 % smaller, negative levels skip it (no gain at
// all), and LZ4 finds nothing to gain (docs/mcap.md, bench/mcap).
#include "compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include "mcap_format.h"
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

std::string zstd_decompress(std::string_view bytes, std::size_t size, const std::string& where) {
  std::string out(size, '\0');
  const std::size_t result = ZSTD_decompress(out.data(), out.size(), bytes.data(), bytes.size());
  if (ZSTD_isError(result)) {
    throw Error(where + ": zstd data cannot be decompressed: " + ZSTD_getErrorName(result));
  }
  if (result != size) {
    throw Error(where + ": expected " + std::to_string(size) + " bytes after decompression, got " +
                std::to_string(result));
  }
  return out;
}

std::string lz4_decompress(std::string_view bytes, std::size_t size, const std::string& where) {
  LZ4F_dctx* context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
    throw Error(where + ": cannot create an LZ4 decompression context");
  }
  std::string out(size, '\0');
  std::size_t written = 0;
  std::size_t read = 0;
  std::size_t hint = 1;
  while (hint != 0 && read < bytes.size()) {
    std::size_t out_size = out.size() - written;
    std::size_t in_size = bytes.size() - read;
    hint = LZ4F_decompress(context, out.data() + written, &out_size, bytes.data() + read, &in_size,
                           nullptr);
    if (LZ4F_isError(hint)) {
      LZ4F_freeDecompressionContext(context);
      throw Error(where + ": lz4 data cannot be decompressed: " + LZ4F_getErrorName(hint));
    }
    written += out_size;
    read += in_size;
    if (out_size == 0 && in_size == 0) break;
  }
  LZ4F_freeDecompressionContext(context);
  if (hint != 0 || written != size) {
    throw Error(where + ": expected " + std::to_string(size) +
                " bytes in a complete LZ4 frame, got " + std::to_string(written));
  }
  return out;
}

}  // namespace

std::string compress(std::string_view compression, std::string_view bytes) {
  if (compression == kZstd) return zstd_compress(bytes);
  if (compression == kLz4) return lz4_compress(bytes);
  return std::string(bytes);
}

std::string decompress(std::string_view compression, std::string_view bytes, std::size_t size,
                       const std::string& where) {
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
