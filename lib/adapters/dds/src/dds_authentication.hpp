// Who authenticated on a secure DDS segment (DDS Security, docs/security.md), as Fast DDS 2.9 tells
// a participant's listener (internal to the DDS adapter and the federation's DDS link):
//   - onParticipantAuthentication AUTHORIZED: the remote participant completed the PKI-DH
//     handshake, so it holds the certificate its GUID prefix follows from
//     (cosmic/certificate_subject.hpp); kept until the participant is removed;
//   - onParticipantAuthentication UNAUTHORIZED: it was refused: a participant without DDS Security
//     on a domain whose governance does not allow unauthenticated participants (Fast DDS 2.9.1
//     reports it so, seen with a plain participant beside a secure one), or one whose certificate,
//     handshake or permissions failed. Counted once per participant GUID however many of this
//     segment's participants refuse it, the last one kept, logged once every 10 s at most;
//   - on_participant_discovery: the subject a participant claims (its identity token's dds.cert.sn),
//     its own word only, and its name; both only for log lines.
//
// Threads: Fast DDS's listener threads call discovered() and authenticated(); any thread reads.
// One mutex guards everything; nothing here is on a forwarding path.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <string>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/rtps/participant/ParticipantDiscoveryInfo.h>

#include "cosmic/log.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic::dds_detail {

// A GUID as Fast DDS prints it: "01.0f.7f.01.db.6d.36.cb.00.00.00.00|0.0.1.c1".
std::string guid_text(const eprosima::fastrtps::rtps::GUID_t& guid);

class ParticipantAuthentications {
 public:
  // `log_prefix`: "DDS segment NAME: "; refusals are logged only when `log_refusals`.
  ParticipantAuthentications(std::string log_prefix, Logger& log, bool log_refusals)
      : prefix_(std::move(log_prefix)), log_(log), log_refusals_(log_refusals) {}

  void discovered(const eprosima::fastrtps::rtps::ParticipantDiscoveryInfo& info);
  void authenticated(const eprosima::fastrtps::rtps::ParticipantAuthenticationInfo& info);

  // This participant's last decision since it was discovered: authorized, refused, or none yet
  // (pending; also after it was dropped or removed, until its next handshake ends).
  enum class State { pending, authorized, refused };
  State state(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const;
  // The subject the participant claims in its identity token (unproven), empty when none.
  std::string claimed_subject(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const;
  // `unauthenticated` (participants refused) and `last_unauthenticated` (the last one's GUID).
  void report(AdapterStatistics& statistics) const;

 private:
  struct Claim {
    std::string subject;
    std::string name;
  };
  const std::string prefix_;
  Logger& log_;
  const bool log_refusals_;
  mutable std::mutex mutex_;
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> authorized_;
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> refused_now_;  // refused since discovered (bounded)
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, Claim> claims_;
  // The participants counted as refused, oldest first (bounded: a flood of new GUIDs is each counted).
  std::deque<eprosima::fastrtps::rtps::GUID_t> refused_order_;
  std::set<eprosima::fastrtps::rtps::GUID_t> refused_;
  std::uint64_t refused_count_ = 0;
  std::string last_refused_;
  Nanos last_log_ = Nanos::min();
};

// A participant listener that only tells `authentications` (the federation's participant).
class AuthenticationListener final : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  explicit AuthenticationListener(ParticipantAuthentications& authentications) : authentications_(authentications) {}
  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    authentications_.discovered(info);
  }
  void onParticipantAuthentication(eprosima::fastdds::dds::DomainParticipant*,
                                   eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    authentications_.authenticated(info);
  }

 private:
  ParticipantAuthentications& authentications_;
};

}  // namespace cosmic::dds_detail
