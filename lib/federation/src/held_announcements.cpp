#include "cosmic/held_announcements.hpp"

#include <algorithm>
#include <chrono>

namespace cosmic {

bool HeldAnnouncements::hold(FederationMessage message, const ParticipantKey& participant, std::string participant_text,
                             Nanos now) {
  const auto same_writer = [&](const Held& h) { return h.message.source == message.source; };
  if (auto it = std::find_if(held_.begin(), held_.end(), same_writer); it != held_.end()) {
    // Newer from the same writer (so the same participant): it replaces the held one and waits
    // where that one waited.
    it->message = std::move(message);
    return true;
  }
  if (held_.size() >= capacity_) return false;
  held_.push_back(Held{std::move(message), participant, std::move(participant_text), now});
  return true;
}

void HeldAnnouncements::forget(const std::string& source) {
  std::erase_if(held_, [&](const Held& h) { return h.message.source == source; });
}

std::vector<FederationMessage> HeldAnnouncements::release(Nanos now, const StateOf& state_of, const Judge& judge) {
  std::vector<FederationMessage> out;
  std::vector<Held> still;
  for (Held& held : held_) {
    switch (state_of(held.participant)) {
      case SenderAuthentication::authorized:
        judge(held.participant, held.message);
        out.push_back(std::move(held.message));
        continue;
      case SenderAuthentication::refused:
        held.message.refusal = held.participant_text + " did not authenticate";
        out.push_back(std::move(held.message));
        continue;
      case SenderAuthentication::pending:
        break;
    }
    if (!held.reported && now - held.since >= report_after_) {
      held.reported = true;
      FederationMessage report = held.message;
      report.awaiting_authentication = true;
      report.refusal = held.participant_text + " has not authenticated in " +
                       std::to_string(std::chrono::duration_cast<std::chrono::seconds>(report_after_).count()) +
                       " s (its announcement waits for the handshake)";
      out.push_back(std::move(report));
    }
    still.push_back(std::move(held));
  }
  held_ = std::move(still);
  return out;
}

}  // namespace cosmic
