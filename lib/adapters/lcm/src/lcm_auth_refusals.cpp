#include "lcm_auth_refusals.hpp"

#include <vector>

namespace cosmic::lcm_detail {
namespace {
constexpr Nanos kRefusalLogPause = std::chrono::seconds(10);  // at most one line per kind in this time
}  // namespace

Result<LcmAuthVerifier> make_verifier(const LcmAuthSpec& auth) {
  std::vector<std::span<const std::uint8_t>> keys{auth.key.bytes()};
  for (const SecretKey& accepted : auth.accepted) keys.push_back(accepted.bytes());
  return LcmAuthVerifier::make(keys, auth.window);
}

InboundProblem LcmAuthRefusals::refuse(const std::string& channel, const std::string& from, const LcmAuthCheck& checked,
                                       Nanos now) {
  const bool unauthenticated = checked.verdict == LcmAuthVerdict::unauthenticated;
  (unauthenticated ? unauthenticated_ : replayed_).fetch_add(1, std::memory_order_relaxed);
  const InboundProblem problem = unauthenticated ? InboundProblem::unauthenticated : InboundProblem::replayed;
  Nanos& last = unauthenticated ? last_unauthenticated_log_ : last_replayed_log_;
  if (last != Nanos::min() && now - last < kRefusalLogPause) return problem;
  last = now;
  const std::string window = std::to_string(window_.count() / 1'000'000) + " ms";
  const std::string why = unauthenticated   ? "no valid authentication tag"
                          : checked.crowded ? "more than " + std::to_string(LcmAuthVerifier::kMaxSenders) +
                                                  " senders within the window (" + window + ")"
                                            : "sent before, or " + std::to_string(checked.skew_ns / 1'000'000) +
                                                  " ms from this host's clock (window " + window + ")";
  log_.log(LogLevel::warning, prefix_ + "dropped a message of channel " + channel + " from " + from + ": " + why +
                                  " (counted as " + to_string(checked.verdict) + "; at most one such line every 10 s)");
  return problem;
}

void LcmAuthRefusals::report(AdapterStatistics& statistics) const {
  statistics.transport.push_back(TransportCounter{"unauthenticated", unauthenticated_.load(std::memory_order_relaxed)});
  statistics.transport.push_back(TransportCounter{"replayed", replayed_.load(std::memory_order_relaxed)});
}

}  // namespace cosmic::lcm_detail
