// FederationView (cosmic/federation_view.hpp) and what it gives admission: peers join, leave and
// are lost; a peer describes only itself; what alive peers reserve on a shared network is summed
// into this gateway's admission (IP load, CAN frames in the response-time analysis).
#include <gtest/gtest.h>

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
  a.segments.push_back(AnnouncedSegment{"backbone", SegmentType::dds, "dds:domain=0", 0.5, lan_load, {}});
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

TEST(FederationView, PeersJoinAreLostComeBackAndLeave) {
  FederationView view(kSelf);
  EXPECT_TRUE(view.apply(said(peer(0x22, "gw2", 0.1), "w2"), Nanos(1s)));
  EXPECT_TRUE(view.apply(said(peer(0x33, "gw3", 0.2), "w3"), Nanos(1s)));
  ASSERT_EQ(view.alive_peers(), 2u);
  EXPECT_NEAR(view.reservations_for({lan()}).at("lan").load, 0.3, 1e-9);

  EXPECT_TRUE(view.apply({Kind::lost, "w2", 0, {}}, Nanos(5s)));
  EXPECT_EQ(view.peers().at(0x22).state, PeerState::lost);
  EXPECT_NEAR(view.reservations_for({lan()}).at("lan").load, 0.2, 1e-9) << "a lost gateway's reservations are released";
  EXPECT_TRUE(view.apply({Kind::alive, "w2", 0, {}}, Nanos(6s)));
  EXPECT_NEAR(view.reservations_for({lan()}).at("lan").load, 0.3, 1e-9) << "and taken again when it is back";

  EXPECT_TRUE(view.apply({Kind::withdrawn, "w3", 0, {}}, Nanos(7s)));
  EXPECT_EQ(view.peers().at(0x33).state, PeerState::left);
  EXPECT_FALSE(view.apply({Kind::lost, "w3", 0, {}}, Nanos(8s))) << "left stays left";
  EXPECT_FALSE(view.apply({Kind::alive, "w3", 0, {}}, Nanos(8s))) << "left stays left until it announces again";
  EXPECT_EQ(view.peers().at(0x33).state, PeerState::left);
  EXPECT_NEAR(view.reservations_for({lan()}).at("lan").load, 0.1, 1e-9);
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
  EXPECT_NEAR(view.reservations_for({lan()}).at("lan").load, 0.1, 1e-9) << "nothing refused reached admission";
}

TEST(FederationView, OlderRevisionsAreStale) {
  FederationView view(kSelf);
  ASSERT_TRUE(view.apply(said(peer(0x22, "gw2", 0.1, 5), "w2"), Nanos(1s)));
  EXPECT_FALSE(view.apply(said(peer(0x22, "gw2", 0.4, 4), "w2"), Nanos(2s)));
  EXPECT_FALSE(view.apply(said(peer(0x22, "gw2", 0.4, 5), "w2"), Nanos(2s)));
  EXPECT_EQ(view.counters().stale, 2u);
  EXPECT_TRUE(view.apply(said(peer(0x22, "gw2", 0.2, 6), "w2"), Nanos(3s)));
  EXPECT_NEAR(view.reservations_for({lan()}).at("lan").load, 0.2, 1e-9);
}

TEST(FederationView, SharedNetworksAreMatchedByIdentity) {
  FederationView view(kSelf);
  Announcement a = peer(0x22, "gw2", 0.1);
  a.segments.push_back(AnnouncedSegment{"other-domain", SegmentType::dds, "dds:domain=5", 0.5, 0.3, {}});
  AnnouncedSegment bus{"chassis", SegmentType::can, "can:body", 0.7, 0.05, {}};
  bus.frames.push_back(AnnouncedFrame{"steer", 0x00A0FFFF, true, 8, Nanos(10ms), Nanos(0)});
  a.segments.push_back(bus);
  Announcement b = peer(0x33, "gw3", 0.0);
  b.segments.push_back(bus);  // the same frame announced twice counts once
  b.segments.back().frames.push_back(AnnouncedFrame{"door", 0x300, false, 2, Nanos(100ms), Nanos(0)});
  ASSERT_TRUE(view.apply(said(a, "w2"), Nanos(1s)));
  ASSERT_TRUE(view.apply(said(b, "w3"), Nanos(1s)));

  SegmentSpec body = can_segment("body-can");
  body.network = "body";
  SegmentSpec alone = can_segment("private-can");  // no network key: this gateway's alone
  const auto r = view.reservations_for({lan(), body, alone});
  EXPECT_NEAR(r.at("lan").load, 0.1, 1e-9) << "domain 5 is another network";
  ASSERT_EQ(r.at("body-can").frames.size(), 2u);
  EXPECT_EQ(r.at("body-can").frames[0].name, "gw2:steer");
  EXPECT_GT(r.at("body-can").load, 0.0);
  EXPECT_EQ(r.count("private-can"), 0u);
}

TEST(FederationAdmission, OtherGatewaysLoadOnASharedNetworkCounts) {
  KnowledgeBase kb(gateway(), {lan(), lcm_segment("viz")});
  // 29 B + 96 B overhead = 1000 bits every 10 ms: 10% of 1 Mbit/s.
  ChannelSpec mine = channel("mine", 1, ChannelClass::srt, {"viz"}, {"lan"}, 29, Nanos(10ms), Nanos(50ms));
  mine.omission_degree = 1;
  ASSERT_TRUE(kb.bind(mine).bound());
  kb.set_peer_reservations({{"lan", PeerReservations{0.35, {}}}});
  ChannelSpec more = mine;
  more.name = "more";
  more.subject = 2;
  const ChannelReport refused = kb.probe(more);
  EXPECT_EQ(refused.verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(refused, "(other gateways 35.0%)")) << reasons_text(refused);
  EXPECT_NEAR(kb.loads()[0].peers, 0.35, 1e-9);
  EXPECT_NEAR(kb.loads()[0].utilization, 0.45, 1e-9);

  // A peer that joins with more makes a bound channel's numbers fail: shown degraded, still bound.
  kb.set_peer_reservations({{"lan", PeerReservations{0.45, {}}}});
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
  const ChannelSpec brake = channel("brake", 0x100, ChannelClass::hrt, {"body"}, {"lan"}, 8, Nanos(10ms), Nanos(2500us));
  EXPECT_EQ(kb.probe(brake).verdict, Verdict::bound) << reasons_text(kb.probe(brake));
  // Another gateway's two frames of higher priority (identifiers below any COSMIC HRT one).
  PeerReservations theirs;
  theirs.frames.push_back(CanBackgroundFrame{"gw2:steer", 0x001, false, 8, Nanos(5ms), Nanos(0), "gateway gw2"});
  theirs.frames.push_back(CanBackgroundFrame{"gw2:yaw", 0x00000FFF & 0x1FFFFFFF, true, 8, Nanos(5ms), Nanos(0), "gateway gw2"});
  kb.set_peer_reservations({{"body", theirs}});
  const ChannelReport refused = kb.probe(brake);
  EXPECT_EQ(refused.verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(refused, "gw2:steer")) << reasons_text(refused);
  // The etag bits of the peer's extended frame (0xFFF) are not handed out.
  kb.set_peer_reservations({{"body", PeerReservations{0, {theirs.frames[1]}}}});
  ChannelSpec slow = channel("slow", 0x200, ChannelClass::nrt, {"lan"}, {"body"}, 8, Nanos(100ms));
  ASSERT_TRUE(kb.bind(slow).bound());
  EXPECT_NE(kb.etag_of("slow"), std::optional<std::uint16_t>(0xFFF));
  ChannelSpec fixed = slow;
  fixed.name = "fixed";
  fixed.subject = 0x201;
  fixed.etag = 0xFFF;
  EXPECT_TRUE(has_reason(kb.probe(fixed), "another gateway's frames")) << reasons_text(kb.probe(fixed));
}

TEST(FederationAnnouncement, SaysWhatThisGatewayReservesWhere) {
  SegmentSpec body = can_segment("body");
  body.network = "body";
  KnowledgeBase kb(gateway(), {body, lan()});
  ASSERT_TRUE(kb.bind(channel("brake", 0x100, ChannelClass::srt, {"lan"}, {"body"}, 8, Nanos(10ms), Nanos(20ms))).bound());
  kb.set_peer_reservations({{"lan", PeerReservations{0.2, {}}}});
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
  EXPECT_LT(a.segments[1].load, 0.2) << "other gateways' load is not announced as this one's";
  ASSERT_EQ(a.channels.size(), 1u);
  EXPECT_EQ(a.channels[0].hops.size(), 2u);
  EXPECT_TRUE(decode_announcement(encode(a)).announcement) << decode_announcement(encode(a)).error;
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
