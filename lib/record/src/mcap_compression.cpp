// Chunk compression over libzstd and liblz4 (mcap_compression.hpp).
#include "mcap_compression.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <string>

namespace cosmic::mcap_detail {

namespace {

Result<void> decompress_zstd(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) {
  // One-shot: it walks every frame of `in` and fails rather than write past out.size().
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
  if (ZSTD_isError(n)) return Error{std::string("zstd: ") + ZSTD_getErrorName(n)};
  if (n != out.size())
    return Error{"zstd: decompressed to " + std::to_string(n) + " bytes, the chunk says " + std::to_string(out.size())};
  return {};
}

struct Lz4Context {
  LZ4F_dctx* context = nullptr;
  ~Lz4Context() { LZ4F_freeDecompressionContext(context); }
};

Result<void> decompress_lz4(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) {
  Lz4Context lz4;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&lz4.context, LZ4F_VERSION)))
    return Error{"lz4: cannot create a decompression context"};
  std::size_t read = 0;
  std::size_t written = 0;
  std::size_t hint = 1;  // LZ4F_decompress returns 0 once a frame is complete
  while (read < in.size() && hint != 0) {
    std::size_t src_size = in.size() - read;
    std::size_t dst_size = out.size() - written;
    hint = LZ4F_decompress(lz4.context, out.data() + written, &dst_size, in.data() + read, &src_size, nullptr);
    if (LZ4F_isError(hint)) return Error{std::string("lz4: ") + LZ4F_getErrorName(hint)};
    read += src_size;
    written += dst_size;
    // No progress with input left: the output is full and the frame wants to write more.
    if (src_size == 0 && dst_size == 0) break;
  }
  if (hint != 0) return Error{"lz4: the frame is incomplete or larger than the chunk says"};
  if (written != out.size())
    return Error{"lz4: decompressed to " + std::to_string(written) + " bytes, the chunk says " +
                 std::to_string(out.size())};
  return {};
}

}  // namespace

void ZstdCompressor::Free::operator()(ZSTD_CCtx_s* context) const noexcept { ZSTD_freeCCtx(context); }

ZstdCompressor::ZstdCompressor() : context_(ZSTD_createCCtx()) {}

Result<std::size_t> ZstdCompressor::compress(std::span<const std::uint8_t> in, int level,
                                             std::vector<std::uint8_t>& out) {
  if (!context_) return Error{"zstd: cannot create a compression context"};
  if (const std::size_t bound = ZSTD_compressBound(in.size()); out.size() < bound) out.resize(bound);
  const std::size_t n = ZSTD_compressCCtx(context_.get(), out.data(), out.size(), in.data(), in.size(), level);
  if (ZSTD_isError(n)) return Error{std::string("zstd: ") + ZSTD_getErrorName(n)};
  return n;
}

Result<void> decompress_chunk(std::string_view compression, std::span<const std::uint8_t> in,
                              std::span<std::uint8_t> out) {
  if (compression.empty()) {
    if (in.size() != out.size())
      return Error{"uncompressed chunk holds " + std::to_string(in.size()) + " bytes, it says " +
                   std::to_string(out.size())};
    if (!in.empty()) std::memcpy(out.data(), in.data(), in.size());
    return {};
  }
  if (compression == "zstd") return decompress_zstd(in, out);
  if (compression == "lz4") return decompress_lz4(in, out);
  return Error{"unsupported compression '" + std::string(compression) + "' (zstd, lz4 or none)"};
}

}  // namespace cosmic::mcap_detail
