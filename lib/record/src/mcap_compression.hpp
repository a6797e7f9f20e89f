// The compressions of MCAP chunks: zstd both ways (libzstd), LZ4 frames to read (liblz4: other
// writers use it), and "" for none. Internal to cosmic_mcap.
//
// Threads: a ZstdCompressor belongs to its writer's thread; decompress_chunk is pure.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "cosmic/result.hpp"

struct ZSTD_CCtx_s;

namespace cosmic::mcap_detail {

// One zstd context reused chunk after chunk (a context costs more to make than a small chunk
// costs to compress).
class ZstdCompressor {
 public:
  ZstdCompressor();
  // `in` compressed at `level` into the start of `out`, grown to zstd's bound when shorter and never
  // shrunk (a buffer kept from chunk to chunk is neither reallocated nor zeroed again); how many
  // bytes the compressed frame takes.
  Result<std::size_t> compress(std::span<const std::uint8_t> in, int level, std::vector<std::uint8_t>& out);

 private:
  struct Free {
    void operator()(ZSTD_CCtx_s* context) const noexcept;
  };
  std::unique_ptr<ZSTD_CCtx_s, Free> context_;
};

// `in`, compressed as a Chunk record names it ("zstd", "lz4", ""), decompressed into exactly
// out.size() bytes: an error when it is damaged, names another compression, or decompresses to
// more or fewer bytes than that.
Result<void> decompress_chunk(std::string_view compression, std::span<const std::uint8_t> in,
                              std::span<std::uint8_t> out);

}  // namespace cosmic::mcap_detail
