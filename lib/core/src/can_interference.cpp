#include "cosmic/can_interference.hpp"

#include <cstdio>

#include "cosmic/can_background.hpp"
#include "cosmic/can_timing.hpp"

namespace cosmic {

std::map<std::string, std::string> undeclared_interference(const AdmissionReport& report, const std::string& segment,
                                                           std::span<const UnexplainedFrames> unexplained) {
  std::map<std::string, std::string> out;
  for (const ChannelReport& channel : report.channels) {
    if (channel.cls != ChannelClass::hrt || channel.verdict == Verdict::rejected) continue;
    for (const HopReport& hop : channel.hops) {
      if (hop.segment != segment || !hop.can) continue;
      const std::uint32_t ours = arbitration_key(*hop.can);
      std::string reason;
      for (const UnexplainedFrames& f : unexplained) {
        const std::uint32_t theirs =
            arbitration_key(f.can_id, f.extended ? CanIdFormat::extended29 : CanIdFormat::standard11);
        if (f.rate_hz <= 0 || theirs >= ours) continue;
        char rate[32];
        std::snprintf(rate, sizeof rate, "%.1f Hz", f.rate_hz);
        reason += std::string(reason.empty() ? "" : ", ") + can_id_text(f.can_id, f.extended) + " at " + rate;
      }
      if (reason.empty()) continue;
      out[channel.name] = "undeclared frames " + reason + " win arbitration over its identifier " +
                          can_id_text(hop.can->can_id, hop.can->extended) + " on " + segment +
                          ": its response-time analysis did not count them (declare them as the segment's background)";
    }
  }
  return out;
}

}  // namespace cosmic
