#include "cosmic/message_auth.hpp"

#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/params.h>

namespace cosmic {
namespace {

std::string openssl_error(const char* what) {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return what;
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  return std::string(what) + " (" + text + ")";
}

struct MacFree {
  void operator()(EVP_MAC* mac) const noexcept { EVP_MAC_free(mac); }
};

}  // namespace

const char* to_string(MacAlgorithm algorithm) {
  return algorithm == MacAlgorithm::hmac_sha256 ? "HMAC-SHA256" : "AES-128-CMAC";
}

void MessageAuth::ContextFree::operator()(evp_mac_ctx_st* context) const noexcept { EVP_MAC_CTX_free(context); }

MessageAuth::MessageAuth(MacAlgorithm algorithm, std::unique_ptr<evp_mac_ctx_st, ContextFree> context)
    : algorithm_(algorithm), context_(std::move(context)) {}

MessageAuth::~MessageAuth() = default;

Result<MessageAuth> MessageAuth::make(MacAlgorithm algorithm, std::span<const std::uint8_t> key) {
  const bool hmac = algorithm == MacAlgorithm::hmac_sha256;
  if (hmac && (key.size() < 16 || key.size() > 64))
    return Error{"an HMAC-SHA256 key has 16 to 64 bytes, this one " + std::to_string(key.size())};
  if (!hmac && key.size() != 16)
    return Error{"an AES-128-CMAC key has 16 bytes, this one " + std::to_string(key.size())};
  const std::unique_ptr<EVP_MAC, MacFree> mac(EVP_MAC_fetch(nullptr, hmac ? "HMAC" : "CMAC", nullptr));
  if (!mac) return Error{openssl_error(hmac ? "OpenSSL has no HMAC" : "OpenSSL has no CMAC")};
  std::unique_ptr<evp_mac_ctx_st, ContextFree> context(EVP_MAC_CTX_new(mac.get()));
  if (!context) return Error{openssl_error("cannot make a MAC context")};
  char digest[] = "SHA256";
  char cipher[] = "AES-128-CBC";
  const OSSL_PARAM params[] = {hmac ? OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_DIGEST, digest, 0)
                                    : OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_CIPHER, cipher, 0),
                               OSSL_PARAM_construct_end()};
  if (EVP_MAC_init(context.get(), key.data(), key.size(), params) != 1)
    return Error{openssl_error("cannot key the MAC")};
  return MessageAuth(algorithm, std::move(context));
}

bool MessageAuth::compute(std::initializer_list<std::span<const std::uint8_t>> parts, MacBytes& out) noexcept {
  return compute(std::span<const std::span<const std::uint8_t>>(parts.begin(), parts.size()), out);
}

bool MessageAuth::compute(std::span<const std::span<const std::uint8_t>> parts, MacBytes& out) noexcept {
  // No key: restart from the one make() set.
  if (EVP_MAC_init(context_.get(), nullptr, 0, nullptr) != 1) {
    ERR_clear_error();
    return false;
  }
  for (const auto& part : parts) {
    if (!part.empty() && EVP_MAC_update(context_.get(), part.data(), part.size()) != 1) {
      ERR_clear_error();
      return false;
    }
  }
  std::size_t written = 0;
  if (EVP_MAC_final(context_.get(), out.data(), &written, out.size()) != 1 || written != size()) {
    ERR_clear_error();
    return false;
  }
  return true;
}

bool tags_equal(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, std::size_t bytes) noexcept {
  if (a.size() < bytes || b.size() < bytes) return false;
  return CRYPTO_memcmp(a.data(), b.data(), bytes) == 0;
}

}  // namespace cosmic
