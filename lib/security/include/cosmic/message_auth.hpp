// Message authentication codes over OpenSSL's EVP_MAC (libcrypto 3): HMAC-SHA256 for LCM envelopes
// (issue 36, item 3) and AES-128-CMAC for SecOC on CAN (item 4). A MessageAuth is keyed once and
// then computes one tag after another over a message given in parts; each computation restarts
// from the stored key (EVP_MAC_init with no key), so nothing of the previous message carries over.
//
// Threads: an instance is used by one thread at a time (its context is mutable state); each sender
// and each receive thread keeps its own. make() may be called from any thread. compute() returns a
// value and never throws; it allocates what OpenSSL allocates when it restarts a context (a few
// small blocks for HMAC, none for CMAC).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <span>
#include <string>

#include "cosmic/result.hpp"

struct evp_mac_ctx_st;

namespace cosmic {

enum class MacAlgorithm : std::uint8_t { hmac_sha256, aes128_cmac };
const char* to_string(MacAlgorithm algorithm);

inline constexpr std::size_t kMaxMacSize = 32;  // HMAC-SHA256; AES-CMAC gives 16
using MacBytes = std::array<std::uint8_t, kMaxMacSize>;

class MessageAuth {
 public:
  // The MAC of `algorithm` keyed with `key` (HMAC: 16 to 64 bytes; CMAC: exactly 16), or why
  // OpenSSL cannot provide it.
  static Result<MessageAuth> make(MacAlgorithm algorithm, std::span<const std::uint8_t> key);

  MessageAuth(MessageAuth&&) noexcept = default;
  MessageAuth& operator=(MessageAuth&&) noexcept = default;
  ~MessageAuth();

  MacAlgorithm algorithm() const noexcept { return algorithm_; }
  std::size_t size() const noexcept { return algorithm_ == MacAlgorithm::hmac_sha256 ? 32 : 16; }

  // The full MAC of the parts, back to back, in `out` (size() bytes of it); false when OpenSSL
  // fails (then `out` is meaningless: a receiver must treat the message as unauthenticated).
  bool compute(std::initializer_list<std::span<const std::uint8_t>> parts, MacBytes& out) noexcept;
  bool compute(std::span<const std::span<const std::uint8_t>> parts, MacBytes& out) noexcept;

 private:
  struct ContextFree {
    void operator()(evp_mac_ctx_st* context) const noexcept;
  };
  MessageAuth(MacAlgorithm algorithm, std::unique_ptr<evp_mac_ctx_st, ContextFree> context);

  MacAlgorithm algorithm_;
  std::unique_ptr<evp_mac_ctx_st, ContextFree> context_;
};

// Whether the first `bytes` of two tags are equal, in time independent of where they differ.
bool tags_equal(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, std::size_t bytes) noexcept;

}  // namespace cosmic
