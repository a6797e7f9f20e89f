// FederationView (cosmic/federation_view.hpp) and what it gives admission: peers join, leave and
// are lost; a peer describes only itself; what alive peers reserve on a shared network is summed
// into this gateway's admission (IP load, CAN frames in the response-time analysis).
#include <gtest/gtest.h>

#include <algorithm>

#include "cosmic/federation.hpp"
#include "cosmic/federation_view.hpp"
#include "cosmic/knowledge_base.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using namespace cosmic::test;
using Kind = FederationMessage::Kind;

constexpr std::uint64_t kSelf = 0x1111;

Announcement peer(std::uint64_t id, const std::string& name, double lan_load, std::uint64_t revision = 1) {
  Announcement a;
  a.gateway = id;
  a.name = name;
  a.revision = revision;
  a.segments.push_back(
      AnnouncedSegment{"backbone", SegmentType::dds, "dds:domain=0", 0.5, lan_load, lan_load * 1e6, {}});
  return a;
}

FederationMessage said(const Announcement& a, const std::string& source) {
  return FederationMessage{Kind::announcement, source, a.gateway, encode(a)};
}

SegmentSpec lan() {
  SegmentSpec s = dds_segment("lan", 1ms, false);
  s.bandwidth = BitRate{1'000'000};
  s.max_utilization = 0.5;
  return s;
}

// What the alive peers reserve on domain 0, as a share of a 1 Mbit/s network.
double lan_bps(const FederationView& view) {
  const PeerNetworks r = view.reservations();
  const auto found = r.find("dds:domain=0");
  return found == r.end() ? 0.0 : found->second.bits_per_second / 1e6;
}

TEST(FederationView, PeersJoinAreLostComeBackAndLeave) {
  FederationView view(kSelf);
  EXPECT_TRUE(view.apply(said(peer(0x22, "gw2", 0.1), "w2"), Nanos(1s)));
  EXPECT_TRUE(view.apply(said(peer(0x33, "gw3", 0.2), "w3"), Nanos(1s)));
  ASSERT_EQ(view.alive_peers(), 2u);
  EXPECT_NEAR(lan_bps(view), 0.3, 1e-9);

  EXPECT_TRUE(view.apply({Kind::lost, "w2", 0, {}}, Nanos(5s)));
  EXPECT_EQ(view.peers().at(0x22).state, PeerState::lost);
  EXPECT_NEAR(lan_bps(view), 0.2, 1e-9) << "a lost gateway's reservations are released";
  EXPECT_TRUE(view.apply({Kind::alive, "w2", 0, {}}, Nanos(6s)));
  EXPECT_NEAR(lan_bps(view), 0.3, 1e-9) << "and taken again when it is back";

  EXPECT_TRUE(view.apply({Kind::withdrawn, "w3", 0, {}}, Nanos(7s)));
  EXPECT_EQ(view.peers().at(0x33).state, PeerState::left);
  EXPECT_FALSE(view.apply({Kind::lost, "w3", 0, {}}, Nanos(8s))) << "left stays left";
  EXPECT_FALSE(view.apply({Kind::alive, "w3", 0, {}}, Nanos(8s))) << "left stays left until it announces again";
  EXPECT_EQ(view.peers().at(0x33).state, PeerState::left);
  EXPECT_NEAR(lan_bps(view), 0.1, 1e-9);
  view.forget_before(Nanos(100s));
  EXPECT_EQ(view.peers().size(), 1u);
  EXPECT_FALSE(view.apply({Kind::lost, "unknown-writer", 0, {}}, Nanos(9s)));
}

TEST(FederationView, APeerDescribesOnlyItself) {
  FederationView view(kSelf, 3);
  ASSERT_TRUE(view.apply(said(peer(0x22, "gw2", 0.1), "w2"), Nanos(1s)));
  std::string why;
  // Filed under another id than it names.
  FederationMessage foreign = said(peer(0x44, "gw4", 0.1), "w4");
  foreign.key = 0x45;
  EXPECT_FALSE(view.apply(foreign, Nanos(2s), &why));
  EXPECT_NE(why.find("filed under"), std::string::npos) << why;
  // This gateway's own id.
  EXPECT_FALSE(view.apply(said(peer(kSelf, "me", 0.4), "w9"), Nanos(2s), &why));
  EXPECT_NE(why.find("own id"), std::string::npos) << why;
  // An alive gateway's id from another writer.
  EXPECT_FALSE(view.apply(said(peer(0x22, "gw2-spoof", 0.9, 5), "w-evil"), Nanos(2s), &why));
  EXPECT_NE(why.find("another writer"), std::string::npos) << why;
  EXPECT_EQ(view.peers().at(0x22).announcement.name, "gw2");
  // Malformed.
  EXPECT_FALSE(view.apply({Kind::announcement, "w5", 0x55, "{\"format\": 1}"}, Nanos(2s), &why));
  EXPECT_FALSE(why.empty());
  // Beyond max_peers.
  ASSERT_TRUE(view.apply(said(peer(0x66, "gw6", 0.0), "w6"), Nanos(2s)));
  ASSERT_TRUE(view.apply(said(peer(0x77, "gw7", 0.0), "w7"), Nanos(2s)));
  EXPECT_FALSE(view.apply(said(peer(0x88, "gw8", 0.0), "w8"), Nanos(2s), &why));
  EXPECT_NE(why.find("more than 3 gateways"), std::string::npos) << why;
  EXPECT_EQ(view.counters().refused, 5u);
  EXPECT_NEAR(lan_bps(view), 0.1, 1e-9) << "nothing refused reached admission";
}

// On a secure segment the transport says who authenticated: a listed gateway's subject is kept
// with it; an unlisted one's announcement is refused and counted like any other, reserving nothing
// and waiting for no takeover, even when it names an alive gateway's id.
TEST(FederationView, WhatTheTransportRefusesIsCountedAndNeverApplied) {
  FederationView view(kSelf);
  FederationMessage listed = said(peer(0x22, "gw2", 0.1), "w2");
  listed.subject = "/O=cosmic/CN=gateway-b";
  ASSERT_TRUE(view.apply(listed, Nanos(1s)));
  EXPECT_EQ(view.peers().at(0x22).subject, "/O=cosmic/CN=gateway-b");
  std::string why;
  for (const std::uint64_t id : {std::uint64_t{0x33}, std::uint64_t{0x22}}) {
    FederationMessage unlisted = said(peer(id, "gw3", 0.4, 7), "w3");
    unlisted.refusal = "authenticated as /O=cosmic/CN=gateway-c, which gateway.federation.peers does not list";
    EXPECT_FALSE(view.apply(unlisted, Nanos(2s), &why));
    EXPECT_EQ(why, unlisted.refusal + " (from writer w3)");
  }
  EXPECT_EQ(view.counters().refused, 2u);
  EXPECT_EQ(view.counters().last_refusal, why);
  EXPECT_EQ(view.peers().size(), 1u);
  EXPECT_EQ(view.pending_takeovers(), 0u);
  EXPECT_FALSE(view.apply({Kind::lost, "w2-other", 0, {}}, Nanos(3s)));
  EXPECT_NEAR(lan_bps(view), 0.1, 1e-9) << "the unlisted gateway's reservation counted";
}

TEST(FederationView, OlderRevisionsAreStale) {
  FederationView view(kSelf);
  ASSERT_TRUE(view.apply(said(peer(0x22, "gw2", 0.1, 5), "w2"), Nanos(1s)));
  EXPECT_FALSE(view.apply(said(peer(0x22, "gw2", 0.4, 4), "w2"), Nanos(2s)));
  EXPECT_FALSE(view.apply(said(peer(0x22, "gw2", 0.4, 5), "w2"), Nanos(2s)));
  EXPECT_EQ(view.counters().stale, 2u);
  EXPECT_TRUE(view.apply(said(peer(0x22, "gw2", 0.2, 6), "w2"), Nanos(3s)));
  EXPECT_NEAR(lan_bps(view), 0.2, 1e-9);
}

TEST(FederationView, OneGatewayPerWriterAndTakeoverWhenTheOldWriterGoes) {
  FederationView view(kSelf);
  ASSERT_TRUE(view.apply(said(peer(0x22, "gw2", 0.1), "w2"), Nanos(1s)));
  std::string why;
  // The same writer filing a second gateway: refused before its body is even decoded.
  EXPECT_FALSE(view.apply({Kind::announcement, "w2", 0x23, "not even JSON"}, Nanos(2s), &why));
  EXPECT_NE(why.find("one gateway per writer"), std::string::npos) << why;
  // gw2 rejoined with a new writer while the old one is still matched: waits, then takes over.
  EXPECT_FALSE(view.apply(said(peer(0x22, "gw2", 0.3, 1), "w2-new"), Nanos(3s), &why));
  EXPECT_NEAR(lan_bps(view), 0.1, 1e-9);
  EXPECT_TRUE(view.apply({Kind::lost, "w2", 0, {}}, Nanos(4s)));
  EXPECT_EQ(view.peers().at(0x22).state, PeerState::alive);
  EXPECT_EQ(view.peers().at(0x22).source, "w2-new");
  EXPECT_NEAR(lan_bps(view), 0.3, 1e-9);
  EXPECT_EQ(view.pending_takeovers(), 0u);
}

TEST(FederationView, ASpooferThatWentTakesNothingOver) {
  FederationView view(kSelf);
  ASSERT_TRUE(view.apply(said(peer(0x22, "gw2", 0.1), "w2"), Nanos(1s)));
  EXPECT_FALSE(view.apply(said(peer(0x22, "gw2", 0.9, 9), "w-evil"), Nanos(2s)));
  EXPECT_EQ(view.pending_takeovers(), 1u);
  EXPECT_FALSE(view.apply({Kind::lost, "w-evil", 0, {}}, Nanos(3s)));
  EXPECT_EQ(view.pending_takeovers(), 0u);
  EXPECT_TRUE(view.apply({Kind::withdrawn, "w2", 0, {}}, Nanos(4s)));
  EXPECT_EQ(view.peers().at(0x22).state, PeerState::left);
  EXPECT_NEAR(lan_bps(view), 0.0, 1e-9);
}

TEST(FederationView, AClaimOfALowerIdCountsAtOnceOneOfAHigherIdOnlyWhenCommitted) {
  FederationView view(0x50);
  Announcement lower = peer(0x10, "gw-low", 0.1);
  lower.claim = lower.segments;
  lower.claim->front().reserved_bps = 250'000;  // 10% now, 25% once its bind is committed
  Announcement higher = peer(0x90, "gw-high", 0.1);
  higher.claim = higher.segments;
  higher.claim->front().reserved_bps = 400'000;
  ASSERT_TRUE(view.apply(said(lower, "w-low"), Nanos(1s)));
  ASSERT_TRUE(view.apply(said(higher, "w-high"), Nanos(1s)));
  // The lower id goes first: its claim counts; the higher one waits for this gateway's bind.
  EXPECT_NEAR(lan_bps(view), 0.25 + 0.1, 1e-9);
  EXPECT_TRUE(view.shared("dds:domain=0"));
  EXPECT_FALSE(view.shared("dds:domain=9"));
}

TEST(FederationView, SharedNetworksAreMatchedByIdentity) {
  FederationView view(kSelf);
  Announcement a = peer(0x22, "gw2", 0.1);
  a.segments.push_back(AnnouncedSegment{"other-domain", SegmentType::dds, "dds:domain=5", 0.5, 0.3, 300'000, {}});
  a.segments.push_back(AnnouncedSegment{"private",
                                        SegmentType::can,
                                        "",
                                        0.7,
                                        0.2,
                                        0,
                                        {AnnouncedFrame{"x", 0x10, false, 8, Nanos(1ms), Nanos(0), std::nullopt}}});
  AnnouncedSegment bus{"chassis", SegmentType::can, "can:body", 0.7, 0.05, 0, {}};
  bus.frames.push_back(AnnouncedFrame{"steer", 0x00A0FFFF, true, 8, Nanos(10ms), Nanos(0), std::nullopt});
  a.segments.push_back(bus);
  // gw3 announces the same identifier lighter (a longer period) and heavier (a larger jitter): it
  // counts once, with the heavier of each, so no peer can hide another's frame.
  Announcement b = peer(0x33, "gw3", 0.0);
  AnnouncedSegment their_bus{"chassis", SegmentType::can, "can:body", 0.7, 0.05, 0, {}};
  their_bus.frames.push_back(AnnouncedFrame{"steer", 0x00A0FFFF, true, 4, Nanos(1s), Nanos(2ms), std::nullopt});
  their_bus.frames.push_back(AnnouncedFrame{"door", 0x300, false, 2, Nanos(100ms), Nanos(0), std::nullopt});
  b.segments.push_back(their_bus);
  ASSERT_TRUE(view.apply(said(a, "w2"), Nanos(1s)));
  ASSERT_TRUE(view.apply(said(b, "w3"), Nanos(1s)));

  const PeerNetworks r = view.reservations();
  EXPECT_NEAR(r.at("dds:domain=0").bits_per_second, 100'000, 1e-6);
  EXPECT_NEAR(r.at("dds:domain=5").bits_per_second, 300'000, 1e-6) << "domain 5 is another network";
  EXPECT_EQ(r.count(""), 0u) << "a bus without a network name is its gateway's alone";
  const auto& frames = r.at("can:body").frames;
  ASSERT_EQ(frames.size(), 2u);
  const auto steer = std::find_if(frames.begin(), frames.end(), [](const auto& f) { return f.can_id == 0x00A0FFFF; });
  ASSERT_NE(steer, frames.end());
  EXPECT_EQ(steer->name, "gw2:steer");
  EXPECT_EQ(steer->period, Nanos(10ms));
  EXPECT_EQ(steer->length, 8u);
  EXPECT_EQ(steer->jitter, Nanos(2ms));
}

TEST(FederationAdmission, OtherGatewaysLoadOnASharedNetworkCounts) {
  KnowledgeBase kb(gateway(), {lan(), lcm_segment("viz")});
  // 29 B + 96 B overhead = 1000 bits every 10 ms: 10% of 1 Mbit/s.
  ChannelSpec mine = channel("mine", 1, ChannelClass::srt, {"viz"}, {"lan"}, 29, Nanos(10ms), Nanos(50ms));
  mine.omission_degree = 1;
  ASSERT_TRUE(kb.bind(mine).bound());
  // 350 kbit/s of this 1 Mbit/s network, wherever the others declared its bandwidth; another
  // network (domain 1) is not this segment's.
  kb.set_peer_reservations(
      {{"dds:domain=0", PeerReservations{350'000, {}, {}}}, {"dds:domain=1", PeerReservations{900'000, {}, {}}}});
  ChannelSpec more = mine;
  more.name = "more";
  more.subject = 2;
  const ChannelReport refused = kb.probe(more);
  EXPECT_EQ(refused.verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(refused, "(other gateways 35.0%)")) << reasons_text(refused);
  EXPECT_NEAR(kb.loads()[0].peers, 0.35, 1e-9);
  EXPECT_NEAR(kb.loads()[0].utilization, 0.45, 1e-9);

  // A peer that joins with more makes a bound channel's numbers fail: shown degraded, still bound.
  kb.set_peer_reservations({{"dds:domain=0", PeerReservations{450'000, {}, {}}}});
  const AdmissionReport report = kb.report();
  const ChannelReport* shown = report.find("mine");
  ASSERT_NE(shown, nullptr);
  EXPECT_EQ(shown->verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(*shown, "other gateways")) << reasons_text(*shown);
  ASSERT_NE(kb.find_bound("mine"), nullptr);

  kb.set_peer_reservations({});
  EXPECT_EQ(kb.probe(more).verdict, Verdict::bound) << reasons_text(kb.probe(more));
}

TEST(FederationAdmission, OtherGatewaysFramesDelayCanChannelsAndKeepTheirEtags) {
  SegmentSpec body = can_segment("body", 125'000);
  body.network = "body";
  KnowledgeBase kb(gateway(100us), {body, dds_segment("lan", 100us)});
  // HRT, reaction 2.5 ms: alone R = 1.28 ms on the 125 kbit/s bus.
  const ChannelSpec brake =
      channel("brake", 0x100, ChannelClass::hrt, {"body"}, {"lan"}, 8, Nanos(10ms), Nanos(2500us));
  EXPECT_EQ(kb.probe(brake).verdict, Verdict::bound) << reasons_text(kb.probe(brake));
  // Another gateway's two frames that win arbitration against ours (priority 0, TxNode 0).
  PeerReservations theirs;
  theirs.frames.push_back(
      CanBackgroundFrame{"gw2:steer", 0x00000001, true, 8, Nanos(5ms), Nanos(0), "gateway gw2", std::nullopt});
  theirs.frames.push_back(
      CanBackgroundFrame{"gw2:yaw", 0x00000002, true, 8, Nanos(5ms), Nanos(0), "gateway gw2", std::nullopt});
  kb.set_peer_reservations({{"can:body", theirs}});
  const ChannelReport refused = kb.probe(brake);
  EXPECT_EQ(refused.verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(refused, "gw2:steer")) << reasons_text(refused);
  EXPECT_GT(kb.loads()[0].peers, 0.1);
  // The etag bits of the peer's extended frame (16383, the first this gateway would hand out) are not.
  const CanBackgroundFrame top{"gw2:log",    0x1F000000 | 16383, true,          8,
                               Nanos(100ms), Nanos(0),           "gateway gw2", std::nullopt};
  kb.set_peer_reservations({{"can:body", PeerReservations{0, {top}, {}}}});
  ChannelSpec slow = channel("slow", 0x200, ChannelClass::nrt, {"lan"}, {"body"}, 8, Nanos(100ms));
  ASSERT_TRUE(kb.bind(slow).bound());
  EXPECT_EQ(kb.etag_of("slow"), std::optional<std::uint16_t>(16382));
  ChannelSpec fixed = slow;
  fixed.name = "fixed";
  fixed.subject = 0x201;
  fixed.etag = 16383;
  EXPECT_TRUE(has_reason(kb.probe(fixed), "another gateway's frame gw2:log")) << reasons_text(kb.probe(fixed));
  // A channel bound here before the peer's frame was known (at start) is shown with the clash.
  kb.set_peer_reservations({});
  ChannelSpec early = slow;
  early.name = "early";
  early.subject = 0x202;
  ASSERT_TRUE(kb.bind(early).bound());
  ASSERT_EQ(kb.etag_of("early"), std::optional<std::uint16_t>(16383));
  kb.set_peer_reservations({{"can:body", PeerReservations{0, {top}, {}}}});
  const AdmissionReport report = kb.report();
  ASSERT_NE(report.find("early"), nullptr);
  EXPECT_EQ(report.find("early")->verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(*report.find("early"), "etag 16383 is also carried by another gateway's frame gw2:log"))
      << reasons_text(*report.find("early"));
}

TEST(FederationAdmission, ABindThatWouldBreakAnotherGatewaysHrtFrameIsRejected) {
  SegmentSpec body = can_segment("body", 500'000);
  body.network = "body";
  KnowledgeBase kb(gateway(100us), {body, dds_segment("lan", 100us)});
  // gw1's HRT frame (priority 0, TxNode 1, etag 16383) every 1 ms, released with 200 us of jitter:
  // R = 0.2 + 0.32 = 0.52 ms alone; its channel there allows up to 0.8 ms.
  const CanBackgroundFrame steer{
      "gw1:steer", (1u << 14) | 16383, true, 8, Nanos(1ms), Nanos(200us), "gateway gw1 (0000000000000001)",
      Nanos(800us)};
  kb.set_peer_reservations({{"can:body", PeerReservations{0, {steer}, {}}}});
  // An NRT frame of 8 bytes loses arbitration to it but may hold the bus when it is queued:
  // R = 0.2 + 0.32 + 0.32 = 0.84 ms > 0.8 ms.
  const ChannelReport refused =
      kb.probe(channel("logbook", 0x600, ChannelClass::nrt, {"lan"}, {"body"}, 8, Nanos(10ms)));
  EXPECT_EQ(refused.verdict, Verdict::rejected);
  EXPECT_TRUE(
      has_reason(refused, "would break the hrt frame gw1:steer of gateway gw1 (0000000000000001): R = 840 us > 800 us"))
      << reasons_text(refused);
  // One byte blocks for 0.18 ms: R = 0.70 ms, within.
  const BindOutcome tiny = kb.bind(channel("tiny", 0x601, ChannelClass::nrt, {"lan"}, {"body"}, 1, Nanos(10ms)));
  EXPECT_TRUE(tiny.bound()) << reasons_text(tiny.report);
}

TEST(FederationAdmission, TheDeadlineIsCheckedAgainstWhatIsAlreadyBoundHere) {
  SegmentSpec body = can_segment("body", 500'000);
  body.network = "body";
  KnowledgeBase kb(gateway(100us), {body, dds_segment("lan", 100us)});
  // A local 1-byte NRT channel first: the bus has a committed analysis when the peer's frame comes.
  ASSERT_TRUE(kb.bind(channel("tiny", 0x601, ChannelClass::nrt, {"lan"}, {"body"}, 1, Nanos(10ms))).bound());
  const CanBackgroundFrame steer{
      "gw1:steer", (1u << 14) | 16383, true, 8, Nanos(1ms), Nanos(200us), "gateway gw1 (0000000000000001)",
      Nanos(800us)};
  kb.set_peer_reservations({{"can:body", PeerReservations{0, {steer}, {}}}});
  // tiny blocks steer by 0.18 ms (R = 0.70 ms); an 8-byte NRT frame would by 0.32 ms (R = 0.84 ms).
  const ChannelReport refused =
      kb.probe(channel("logbook", 0x600, ChannelClass::nrt, {"lan"}, {"body"}, 8, Nanos(10ms)));
  EXPECT_TRUE(has_reason(refused, "would break the hrt frame gw1:steer")) << reasons_text(refused);
  // A channel on the lan only does not touch the bus's analysis.
  EXPECT_EQ(kb.probe(channel("chat", 0x602, ChannelClass::nrt, {"lan"}, {"lan"}, 8, Nanos(10ms))).verdict,
            Verdict::bound);
}

TEST(FederationAnnouncement, AnHrtFrameCarriesTheMostResponseTimeItsChannelAllows) {
  SegmentSpec body = can_segment("body", 500'000);
  body.network = "body";
  KnowledgeBase kb(gateway(100us), {body, dds_segment("lan", 100us)});
  ASSERT_TRUE(
      kb.bind(channel("steer", 0x500, ChannelClass::hrt, {"lan"}, {"body"}, 8, Nanos(1ms), Nanos(800us))).bound());
  const Announcement a = announcement_of(GatewayIdentity{0x42, "gw1"}, kb, 1);
  ASSERT_EQ(a.segments[0].frames.size(), 1u);
  // R = 0.2 (released after 0.1 on lan + 0.1 residence) + 0.32 = 0.52 ms, end to end 0.52 ms: 0.28 ms to spare.
  EXPECT_EQ(a.segments[0].frames[0].jitter, Nanos(200us));
  EXPECT_EQ(a.segments[0].frames[0].deadline, std::optional<Nanos>(Nanos(800us)));
}

TEST(FederationAnnouncement, SaysWhatThisGatewayReservesWhere) {
  SegmentSpec body = can_segment("body");
  body.network = "body";
  KnowledgeBase kb(gateway(), {body, lan()});
  ASSERT_TRUE(
      kb.bind(channel("brake", 0x100, ChannelClass::srt, {"lan"}, {"body"}, 8, Nanos(10ms), Nanos(20ms))).bound());
  const double alone = kb.loads()[1].utilization;
  kb.set_peer_reservations({{"dds:domain=0", PeerReservations{200'000, {}, {}}}});
  const Announcement a = announcement_of(GatewayIdentity{0x42, "gw1"}, kb, 3);
  EXPECT_EQ(a.gateway, 0x42u);
  EXPECT_EQ(a.revision, 3u);
  ASSERT_EQ(a.segments.size(), 2u);
  EXPECT_EQ(a.segments[0].network, "can:body");
  ASSERT_EQ(a.segments[0].frames.size(), 1u);
  EXPECT_EQ(a.segments[0].frames[0].channel, "brake");
  EXPECT_EQ(a.segments[0].frames[0].period, Nanos(10ms));
  EXPECT_GT(a.segments[0].load, 0.0);
  EXPECT_EQ(a.segments[1].network, "dds:domain=0");
  EXPECT_NEAR(a.segments[1].load, alone, 1e-9) << "other gateways' load is not announced as this one's";
  EXPECT_NEAR(a.segments[1].reserved_bps, alone * 1e6, 1e-3);
  EXPECT_FALSE(a.segments[0].frames[0].deadline) << "an SRT channel's frame has no deadline to keep";
  ASSERT_EQ(a.channels.size(), 1u);
  EXPECT_EQ(a.channels[0].hops.size(), 2u);
  EXPECT_TRUE(decode_announcement(encode(a)).announcement) << decode_announcement(encode(a)).error;
}

// gw1 receives `steer` from its front CAN bus and sends it onto the backbone; this gateway receives
// it from the backbone and sends it to its rear bus.
Announcement upstream_gateway(Nanos front_latency, Nanos period = Nanos(10ms)) {
  Announcement a = peer(0x22, "gw1", 0.0);
  a.residence = Nanos(500us);
  AnnouncedChannel steer;
  steer.name = "steer-front";
  steer.subject = 0x77;
  steer.cls = ChannelClass::srt;
  steer.hops = {AnnouncedHop{"front", HopRole::publisher, front_latency},
                AnnouncedHop{"backbone", HopRole::subscriber, Nanos(1ms)}};
  steer.period = period;
  steer.reaction_time = Nanos(20ms);
  steer.payload = 8;
  a.channels.push_back(steer);
  return a;
}

TEST(FederationEndToEnd, AChannelCrossingTwoGatewaysIsAdmittedOverTheWholePath) {
  FederationView view(kSelf);
  // Its events leave gw1 at most 4 ms + 0.5 ms after they were sent on the front bus.
  ASSERT_TRUE(view.apply(said(upstream_gateway(Nanos(4ms)), "w1"), Nanos(1s)));
  const PeerNetworks peers = view.reservations();
  ASSERT_EQ(peers.at("dds:domain=0").senders.size(), 1u);
  EXPECT_EQ(peers.at("dds:domain=0").senders[0].age, std::optional<Nanos>(Nanos(4500us)));

  SegmentSpec backbone = dds_segment("backbone", 1ms, false);
  KnowledgeBase kb(gateway(500us), {backbone, lcm_segment("rear", 2ms)});
  kb.set_peer_reservations(peers);
  ChannelSpec steer = channel("steer", 0x77, ChannelClass::srt, {"backbone"}, {"rear"}, 8, Nanos(10ms), Nanos(20ms));
  // Here alone: 1 + 0.5 + 2 = 3.5 ms; over both gateways 4.5 + 3.5 = 8 ms <= 20 ms.
  const BindOutcome bound = kb.bind(steer);
  ASSERT_TRUE(bound.bound()) << reasons_text(bound.report);
  EXPECT_EQ(bound.report.verdict, Verdict::bound) << reasons_text(bound.report);
  EXPECT_EQ(bound.report.end_to_end.latency, std::optional<Nanos>(Nanos(8ms)));
  EXPECT_EQ(bound.report.end_to_end.local, std::optional<Nanos>(Nanos(3500us)));
  ASSERT_EQ(bound.report.upstream.size(), 1u);
  EXPECT_EQ(bound.report.upstream[0].gateway, "gw1");
  EXPECT_EQ(bound.report.upstream[0].segment, "front");

  // gw1's front bus gets slower (a rebind there): 18 + 0.5 + 3.5 = 22 ms > 20 ms, shown at once.
  view.apply(said(upstream_gateway(Nanos(18ms)), "w1"), Nanos(2s));
  view.apply(said(
                 [] {
                   auto a = upstream_gateway(Nanos(18ms));
                   a.revision = 2;
                   return a;
                 }(),
                 "w1"),
             Nanos(2s));
  kb.set_peer_reservations(view.reservations());
  const AdmissionReport now = kb.report();
  ASSERT_NE(now.find("steer"), nullptr);
  EXPECT_EQ(now.find("steer")->verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(*now.find("steer"), "end-to-end latency through gateway gw1 22 ms > reaction_time 20 ms"))
      << reasons_text(*now.find("steer"));
  // An HRT newcomer on the same path is rejected.
  ChannelSpec hrt = steer;
  hrt.name = "steer-hrt";
  kb.unbind("steer");
  hrt.cls = ChannelClass::hrt;
  const ChannelReport refused = kb.probe(hrt);
  EXPECT_EQ(refused.verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(refused, "through gateway gw1")) << reasons_text(refused);
}

TEST(FederationEndToEnd, AnUpstreamViolatedAtRunTimeDegradesTheChannelHere) {
  FederationView view(kSelf);
  Announcement a = upstream_gateway(Nanos(1ms));
  a.channels[0].violated = true;
  ASSERT_TRUE(view.apply(said(a, "w1"), Nanos(1s)));
  KnowledgeBase kb(gateway(500us), {dds_segment("backbone", 1ms, false), lcm_segment("rear", 2ms)});
  ASSERT_TRUE(
      kb.bind(channel("steer", 0x77, ChannelClass::srt, {"backbone"}, {"rear"}, 8, Nanos(10ms), Nanos(20ms))).bound());
  EXPECT_EQ(kb.report().find("steer")->verdict, Verdict::bound);
  kb.set_peer_reservations(view.reservations());
  const AdmissionReport report = kb.report();
  EXPECT_EQ(report.find("steer")->verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(*report.find("steer"), "gateway gw1 reports channel steer-front violated at run time"))
      << reasons_text(*report.find("steer"));
}

TEST(FederationEndToEnd, ConflictingDefinitionsOfOneSubjectAreMismatchesWithReasons) {
  FederationView view(kSelf);
  // gw1 sends it every 5 ms; this gateway admitted one every 10 ms.
  ASSERT_TRUE(view.apply(said(upstream_gateway(Nanos(1ms), Nanos(5ms)), "w1"), Nanos(1s)));
  KnowledgeBase kb(gateway(500us), {dds_segment("backbone", 1ms, false), lcm_segment("rear", 2ms)});
  kb.set_peer_reservations(view.reservations());
  ChannelSpec steer = channel("steer", 0x77, ChannelClass::srt, {"backbone"}, {"rear"}, 8, Nanos(10ms), Nanos(30ms));
  const ChannelReport report = kb.probe(steer);
  EXPECT_EQ(report.verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(report, "period 5 ms at gateway gw1 (channel steer-front) < 10 ms here"))
      << reasons_text(report);
  EXPECT_TRUE(has_reason(report, "reaction_time 20 ms at gateway gw1 (channel steer-front), 30 ms here"))
      << reasons_text(report);
  // Another subject on the same network is not on that path.
  steer.subject = 0x78;
  EXPECT_TRUE(kb.probe(steer).upstream.empty());
}

TEST(FederationView, APathThroughThisGatewayIsNoUpstream) {
  // gw2 sends `steer` onto the backbone, having received it from gw1 (this gateway) before: a ring.
  FederationView view(0x11);
  Announcement a = upstream_gateway(Nanos(1ms));
  a.channels[0].upstream = {PathHop{"gw-self", "rear", HopRole::publisher, Nanos(1ms), 0x11}};
  ASSERT_TRUE(view.apply(said(a, "w1"), Nanos(1s)));
  EXPECT_TRUE(view.reservations().at("dds:domain=0").senders.empty());
  // Without this gateway on it, the same path is an upstream.
  a.channels[0].upstream[0].gateway_id = 0x99;
  a.revision = 2;
  ASSERT_TRUE(view.apply(said(a, "w1"), Nanos(2s)));
  ASSERT_EQ(view.reservations().at("dds:domain=0").senders.size(), 1u);
  EXPECT_EQ(view.reservations().at("dds:domain=0").senders[0].hops.size(), 2u);
}

TEST(FederationAnnouncement, NetworkIdentities) {
  SegmentSpec d = dds_segment("lan");
  d.dds.domain = 4;
  EXPECT_EQ(network_identity(d), "dds:domain=4");
  d.dds.discovery_server = "10.0.0.1:11811";
  EXPECT_EQ(network_identity(d), "dds:domain=4;server=10.0.0.1:11811");
  SegmentSpec l = lcm_segment("viz");
  l.lcm.url = "udpm://239.255.76.67:7700?ttl=0";
  EXPECT_EQ(network_identity(l), "lcm:239.255.76.67:7700");
  l.lcm.url = "memq://";
  EXPECT_EQ(network_identity(l), "");
  EXPECT_EQ(network_identity(can_segment("c")), "") << "interface names are local";
  SegmentSpec c = can_segment("c");
  c.network = "chassis";
  EXPECT_EQ(network_identity(c), "can:chassis");
}

}  // namespace
}  // namespace cosmic
