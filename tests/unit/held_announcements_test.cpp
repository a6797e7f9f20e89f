// HeldAnnouncements (cosmic/held_announcements.hpp): on a secure federation segment an
// announcement that arrives before its sender's authentication is decided waits for it instead of
// being refused for good; it is judged once authorized, refused once refused, reported once when
// undecided too long, and a newer one or the writer's departure replaces or drops it.
#include <gtest/gtest.h>

#include <map>

#include "cosmic/held_announcements.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using Kind = FederationMessage::Kind;

const ParticipantKey kA{0xb3, 0x18, 1};
const ParticipantKey kB{0xce, 0xc4, 2};

FederationMessage announcement(const std::string& source, const std::string& body) {
  return FederationMessage{Kind::announcement, source, 7, body};
}

// Participants' authentication as a test sets it; the judge marks what it judged.
struct Senders {
  std::map<ParticipantKey, SenderAuthentication> states;
  int judged = 0;
  HeldAnnouncements::StateOf state_of() {
    return [this](const ParticipantKey& key) {
      const auto it = states.find(key);
      return it == states.end() ? SenderAuthentication::pending : it->second;
    };
  }
  HeldAnnouncements::Judge judge() {
    return [this](const ParticipantKey& key, FederationMessage& m) {
      ++judged;
      m.subject = key == kA ? "/O=cosmic/CN=gateway-a" : "/O=cosmic/CN=gateway-b";
    };
  }
};

TEST(HeldAnnouncements, AnAnnouncementBeforeItsSendersHandshakeIsJudgedOnceAuthorized) {
  HeldAnnouncements held(8, 10s);
  Senders senders;
  ASSERT_TRUE(held.hold(announcement("w-a", "first"), kA, "participant A", 0s));
  EXPECT_TRUE(held.release(1s, senders.state_of(), senders.judge()).empty());
  EXPECT_EQ(senders.judged, 0);

  senders.states[kA] = SenderAuthentication::authorized;
  const auto out = held.release(2s, senders.state_of(), senders.judge());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].body, "first");
  EXPECT_EQ(out[0].subject, "/O=cosmic/CN=gateway-a");
  EXPECT_TRUE(out[0].refusal.empty());
  EXPECT_EQ(held.size(), 0u);
  EXPECT_TRUE(held.release(3s, senders.state_of(), senders.judge()).empty());
}

TEST(HeldAnnouncements, ARefusedSenderIsRefusedWithItsParticipantNamed) {
  HeldAnnouncements held(8, 10s);
  Senders senders;
  held.hold(announcement("w-a", "x"), kA, "participant 01.02", 0s);
  senders.states[kA] = SenderAuthentication::refused;
  const auto out = held.release(1s, senders.state_of(), senders.judge());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].refusal, "participant 01.02 did not authenticate");
  EXPECT_EQ(senders.judged, 0);
  EXPECT_EQ(held.size(), 0u);
}

TEST(HeldAnnouncements, UndecidedTooLongIsReportedOnceAndStillReleasedWhenAuthorized) {
  HeldAnnouncements held(8, 10s);
  Senders senders;
  held.hold(announcement("w-a", "x"), kA, "participant A", 0s);
  EXPECT_TRUE(held.release(9s, senders.state_of(), senders.judge()).empty());
  const auto report = held.release(10s, senders.state_of(), senders.judge());
  ASSERT_EQ(report.size(), 1u);
  EXPECT_EQ(report[0].refusal,
            "participant A has not authenticated in 10 s (its announcement waits for the handshake)");
  EXPECT_TRUE(report[0].awaiting_authentication);
  EXPECT_EQ(report[0].source, "w-a") << "the view and the log name the writer and the gateway";
  EXPECT_EQ(report[0].key, 7u);
  EXPECT_TRUE(held.release(20s, senders.state_of(), senders.judge()).empty()) << "reported once";
  held.hold(announcement("w-a", "newer"), kA, "participant A", 21s);
  EXPECT_TRUE(held.release(40s, senders.state_of(), senders.judge()).empty()) << "a replacement is not reported again";

  senders.states[kA] = SenderAuthentication::authorized;
  const auto out = held.release(30s, senders.state_of(), senders.judge());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].refusal.empty());
  EXPECT_EQ(out[0].subject, "/O=cosmic/CN=gateway-a");
  EXPECT_EQ(out[0].body, "newer");
  EXPECT_FALSE(out[0].awaiting_authentication);
}

TEST(HeldAnnouncements, ANewerAnnouncementOfTheSameWriterReplacesTheHeldOne) {
  HeldAnnouncements held(8, 10s);
  Senders senders;
  held.hold(announcement("w-a", "old"), kA, "participant A", 0s);
  held.hold(announcement("w-a", "new"), kA, "participant A", 5s);
  EXPECT_EQ(held.size(), 1u);
  // It waits where the first one started: reported 10 s after the first arrived.
  EXPECT_EQ(held.release(10s, senders.state_of(), senders.judge()).size(), 1u);
  senders.states[kA] = SenderAuthentication::authorized;
  const auto out = held.release(11s, senders.state_of(), senders.judge());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].body, "new");
}

TEST(HeldAnnouncements, OnlyDecidedSendersAreReleasedInTheOrderTheyArrived) {
  HeldAnnouncements held(8, 10s);
  Senders senders;
  held.hold(announcement("w-b", "b"), kB, "participant B", 0s);
  held.hold(announcement("w-a1", "a1"), kA, "participant A", 1s);
  held.hold(announcement("w-a2", "a2"), kA, "participant A", 2s);
  senders.states[kA] = SenderAuthentication::authorized;
  const auto out = held.release(3s, senders.state_of(), senders.judge());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].body, "a1");
  EXPECT_EQ(out[1].body, "a2");
  EXPECT_EQ(held.size(), 1u) << "B's stays held";
}

TEST(HeldAnnouncements, AWriterThatLeftTakesWhatItLeftHeldWithIt) {
  HeldAnnouncements held(8, 10s);
  Senders senders;
  held.hold(announcement("w-a", "x"), kA, "participant A", 0s);
  held.hold(announcement("w-b", "y"), kB, "participant B", 0s);
  held.forget("w-a");
  senders.states[kA] = SenderAuthentication::authorized;
  senders.states[kB] = SenderAuthentication::authorized;
  const auto out = held.release(1s, senders.state_of(), senders.judge());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].body, "y");
}

TEST(HeldAnnouncements, AFloodOfWritersIsBounded) {
  HeldAnnouncements held(2, 10s);
  EXPECT_TRUE(held.hold(announcement("w1", ""), kA, "participant A", 0s));
  EXPECT_TRUE(held.hold(announcement("w2", ""), kA, "participant A", 0s));
  EXPECT_FALSE(held.hold(announcement("w3", ""), kA, "participant A", 0s));
  EXPECT_TRUE(held.hold(announcement("w2", "newer"), kA, "participant A", 0s)) << "a held writer may still replace";
  EXPECT_EQ(held.size(), 2u);
  Senders senders;
  senders.states[kA] = SenderAuthentication::authorized;
  const auto out = held.release(1s, senders.state_of(), senders.judge());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].body, "newer");
  EXPECT_TRUE(held.hold(announcement("w3", ""), kA, "participant A", 2s)) << "released ones free their places";
}

}  // namespace
}  // namespace cosmic
