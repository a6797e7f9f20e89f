#include "dds_authentication.hpp"

#include <chrono>
#include <sstream>

namespace cosmic::dds_detail {
namespace {

namespace rtps = eprosima::fastrtps::rtps;

constexpr Nanos kRefusalLogPause = std::chrono::seconds(10);  // at most one line in this time
// Participants remembered as counted (so three local participants refusing one count it once) and
// claims kept for log lines: bounds against a flood of made-up participants.
constexpr std::size_t kMaxRemembered = 4096;

// Text from the network as a log line may quote it.
std::string printable(const std::string& text) {
  std::string out;
  for (const char c : text.substr(0, 128)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return out;
}

Nanos steady_now() { return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch()); }

}  // namespace

std::string guid_text(const rtps::GUID_t& guid) {
  std::ostringstream out;
  out << guid;
  return out.str();
}

void ParticipantAuthentications::discovered(const rtps::ParticipantDiscoveryInfo& info) {
  const rtps::GuidPrefix_t& prefix = info.info.m_guid.guidPrefix;
  std::lock_guard lock(mutex_);
  if (info.status == rtps::ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
      info.status == rtps::ParticipantDiscoveryInfo::DROPPED_PARTICIPANT) {
    authorized_.erase(prefix);
    refused_now_.erase(prefix);
    claims_.erase(prefix);
    return;
  }
  if (claims_.size() >= kMaxRemembered && !claims_.count(prefix)) return;
  Claim& claim = claims_[prefix];
  claim.name = info.info.m_participantName.to_string();
  for (const auto& property : info.info.identity_token_.properties()) {
    if (property.name() == "dds.cert.sn") claim.subject = property.value();
  }
}

void ParticipantAuthentications::authenticated(const rtps::ParticipantAuthenticationInfo& info) {
  std::unique_lock lock(mutex_);
  if (info.status == rtps::ParticipantAuthenticationInfo::AUTHORIZED_PARTICIPANT) {
    authorized_.insert(info.guid.guidPrefix);
    refused_now_.erase(info.guid.guidPrefix);
    return;
  }
  authorized_.erase(info.guid.guidPrefix);
  if (refused_now_.size() < kMaxRemembered) refused_now_.insert(info.guid.guidPrefix);
  if (!refused_.insert(info.guid).second) return;  // another of this segment's participants counted it
  refused_order_.push_back(info.guid);
  if (refused_order_.size() > kMaxRemembered) {
    refused_.erase(refused_order_.front());
    refused_order_.pop_front();
  }
  ++refused_count_;
  last_refused_ = guid_text(info.guid);
  const Nanos now = steady_now();
  if (!log_refusals_ || (last_log_ != Nanos::min() && now - last_log_ < kRefusalLogPause)) return;
  last_log_ = now;
  std::string who = last_refused_;
  if (const auto claim = claims_.find(info.guid.guidPrefix); claim != claims_.end()) {
    if (!claim->second.name.empty()) who += " (\"" + printable(claim->second.name) + "\")";
    who += claim->second.subject.empty() ? ", which announces no certificate subject"
                                         : ", which claims subject " + printable(claim->second.subject);
  }
  const std::string line = prefix_ + "refused participant " + who +
                           ": it did not authenticate (counted as unauthenticated, " + std::to_string(refused_count_) +
                           " so far; at most one such line every 10 s)";
  lock.unlock();
  log_.log(LogLevel::warning, line);
}

ParticipantAuthentications::State ParticipantAuthentications::state(const rtps::GuidPrefix_t& prefix) const {
  std::lock_guard lock(mutex_);
  if (authorized_.count(prefix) != 0) return State::authorized;
  return refused_now_.count(prefix) != 0 ? State::refused : State::pending;
}

std::string ParticipantAuthentications::claimed_subject(const rtps::GuidPrefix_t& prefix) const {
  std::lock_guard lock(mutex_);
  const auto claim = claims_.find(prefix);
  return claim == claims_.end() ? std::string() : claim->second.subject;
}

void ParticipantAuthentications::report(AdapterStatistics& statistics) const {
  std::lock_guard lock(mutex_);
  statistics.transport.push_back(TransportCounter{"unauthenticated", refused_count_});
  statistics.transport_notes.push_back(TransportNote{"last_unauthenticated", last_refused_});
}

}  // namespace cosmic::dds_detail
