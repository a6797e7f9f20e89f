// The federation transport over Fast DDS 2.9 (docs/federation.md): one participant of its own in
// the federation segment's domain (the segment's transports and discovery), topic
// "cosmic/federation" of type cosmic_federation::Announcement.
//   participant  lease = gateway.federation.lease (announced every lease / 3): the others drop this
//                gateway's participant, and with it its writer, when it is silent that long
//   writer  RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1, asynchronous publishing (announcements are fragmented)
//   reader  the same, with at most FederationView::kDefaultMaxPeers instances of one sample each
// What the reader hears becomes FederationMessages: a sample -> announcement (filed under its
// key, the source being its writer's GUID), a disposed instance -> withdrawn, a writer unmatched
// (its participant's lease expired) -> lost, matched again -> alive. This gateway's own samples
// are dropped by GUID prefix.
// On a secure segment (DDS Security) an announcement counts only from a participant that
// authenticated and, when gateway.federation.peers lists subjects, whose GUID prefix one of them
// gives under PKI-DH (cosmic/certificate_subject.hpp); the message carries the subject, or the
// refusal (FederationMessage::subject, refusal). Without peers, the subject is the one the
// participant claims when its GUID proves it.
//
// Threads: Fast DDS's listener threads queue messages under a mutex (never touching anything
// else); start/publish/withdraw/take run on the owner's control thread.
#pragma once

#include <memory>

#include "cosmic/federation_link.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"

namespace cosmic {

// `segment` is the DDS segment named by gateway.federation.segment; `federation` gives the lease
// and, on a secure segment, the peers.
std::unique_ptr<FederationLink> make_dds_federation_link(const SegmentSpec& segment, const GatewayIdentity& self,
                                                         const FederationSpec& federation, Logger& log);

}  // namespace cosmic
