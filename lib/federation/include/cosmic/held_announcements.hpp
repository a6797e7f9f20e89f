// Announcements that wait for their sender's authentication (a secure federation segment,
// docs/federation.md). A DDS reader may take a sample before the participant listener is told
// that its writer's participant passed the handshake: Fast DDS matches the remote endpoints and
// only then calls the listener, and under load the sample can slip in between. The same happens
// after a participant is dropped and discovered again. A durable announcement arrives once, so
// judging it "not authenticated" then would refuse that gateway until it next changes.
//
// Instead the transport holds it, the newest per writer, until its participant's authentication
// is decided: authorized (then judged against gateway.federation.peers by the caller), refused
// (then refused), or still undecided after `report_after` (then reported as refused once, and
// still held: a handshake that completes later releases it).
//
// No I/O; the owner (the DDS federation link) serializes every call under its own mutex.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "cosmic/federation_view.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

// A participant as the transport names it (DDS: the 12-byte GUID prefix).
using ParticipantKey = std::array<std::uint8_t, 12>;

enum class SenderAuthentication { pending, authorized, refused };

class HeldAnnouncements {
 public:
  using StateOf = std::function<SenderAuthentication(const ParticipantKey&)>;
  // Sets the subject or the refusal of an authorized sender's announcement.
  using Judge = std::function<void(const ParticipantKey&, FederationMessage&)>;

  HeldAnnouncements(std::size_t capacity, Nanos report_after) : capacity_(capacity), report_after_(report_after) {}

  // Holds `message` (an announcement) from `participant`, replacing what its writer left held;
  // `participant_text` names the participant in refusals ("participant 01.0f..."). False when full: the caller counts
  // it as dropped.
  bool hold(FederationMessage message, const ParticipantKey& participant, std::string participant_text, Nanos now);
  // The writer withdrew or was lost: what it left held is stale.
  void forget(const std::string& source);
  // The held announcements whose senders are decided now, judged, oldest first; and a refusal
  // for each one undecided for `report_after` (once per held announcement).
  std::vector<FederationMessage> release(Nanos now, const StateOf& state_of, const Judge& judge);

  std::size_t size() const { return held_.size(); }

 private:
  struct Held {
    FederationMessage message;
    ParticipantKey participant;
    std::string participant_text;
    Nanos since;
    bool reported = false;
  };
  std::size_t capacity_;
  Nanos report_after_;
  std::vector<Held> held_;
};

}  // namespace cosmic
