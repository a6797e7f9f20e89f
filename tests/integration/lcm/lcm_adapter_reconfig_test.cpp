// LCM segment adapter against real LCM peers, continued (see lcm_adapter_test.cpp):
// reconfiguration while events flow, malformed envelopes counted as decode errors, the transport's
// channel name limit, and the envelope decoder the adapter runs (cosmic/lcm_wire.hpp) against what
// lcm-gen encodes. Each adapter test runs in its own network namespace (scripts/netns-run,
// multicast on loopback only) and uses its own multicast port.
#include <lcm/lcm.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cosmic/envelope.hpp"
#include "cosmic/lcm_adapter.hpp"
#include "cosmic/lcm_wire.hpp"
#include "cosmic/transport_limits.hpp"
#include "lcm_adapter_fixture.hpp"

namespace cosmic::lcm_test {
namespace {

TEST_F(LcmAdapterTest, ConfigureWhileFlowingLosesNothingOnOtherChannels) {
  const int port = 7707;
  const std::string url = url_for(port);
  constexpr int kCount = 250;  // peer payloads stay distinct below 256 messages
  auto adapter = make(port);
  const ChannelBinding a = binding(1, "FLOW_IN", HopRole::publisher, LcmEncoding::raw);
  const ChannelBinding t = binding(2, "FLOW_OUT", HopRole::subscriber);
  const ChannelBinding b = binding(3, "EXTRA_IN", HopRole::publisher, LcmEncoding::raw);
  const ChannelBinding c = binding(4, "EXTRA_OUT", HopRole::subscriber);
  const std::vector<std::vector<ChannelBinding>> configs{{a, t}, {a, t, b}, {t, a, c}, {a, t, b, c}};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(configs[0]).ok);

  Child sub(
      {peer(), "sub", "--url", url, "--channel", "FLOW_OUT", "--count", std::to_string(kCount), "--timeout", "20"});
  ASSERT_TRUE(sub.wait_stderr("READY")) << sub.stderr_text();
  Child pub({peer(), "pub", "--url", url, "--channel", "FLOW_IN", "--raw", "--count", std::to_string(kCount), "--size",
             "16", "--rate", "250"});

  // Send on FLOW_OUT and reconfigure the segment over and over while FLOW_IN flows in.
  std::uint32_t sent = 0;
  std::size_t reconfigurations = 0;
  const auto deadline = Clock::now() + 20s;
  while ((sent < kCount || sink_.count(1) < kCount) && Clock::now() < deadline) {
    if (sent < kCount) {
      ++sent;
      ASSERT_EQ(adapter->send(outbound(2, own_pattern(sent, 16), sent)), SendStatus::sent);
    }
    ASSERT_TRUE(adapter->configure(configs[reconfigurations % configs.size()]).ok);
    ++reconfigurations;
    std::this_thread::sleep_for(2ms);  // pacing only
  }
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(1, kCount)) << sink_.count(1);
  EXPECT_GT(reconfigurations, 100u);

  const auto in = sink_.events(1);
  ASSERT_EQ(in.size(), static_cast<std::size_t>(kCount));
  for (std::size_t i = 0; i < in.size(); ++i) EXPECT_EQ(in[i].payload, peer_pattern(i + 1, 16));

  ASSERT_EQ(sub.wait_exit(), std::optional<int>(0)) << sub.stderr_text();
  const auto lines = sub.stdout_lines();
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kCount));
  for (std::uint32_t k = 1; k <= kCount; ++k)
    EXPECT_EQ(nlohmann::json::parse(lines[k - 1])["sequence"].get<std::uint32_t>(), k);

  // An added channel receives; a removed one no longer does.
  ASSERT_TRUE(adapter->configure(configs[1]).ok);
  {
    Child extra({peer(), "pub", "--url", url, "--channel", "EXTRA_IN", "--raw", "--count", "3", "--size", "8"});
    ASSERT_EQ(extra.wait_exit(), std::optional<int>(0));
  }
  ASSERT_TRUE(sink_.wait_events(3, 3));
  const std::size_t extra_before = sink_.count(3);
  ASSERT_TRUE(adapter->configure(configs[0]).ok);
  {
    Child extra({peer(), "pub", "--url", url, "--channel", "EXTRA_IN", "--raw", "--count", "3", "--size", "8"});
    ASSERT_EQ(extra.wait_exit(), std::optional<int>(0));
  }
  // A later message on FLOW_IN marks that the EXTRA_IN ones had their chance to arrive.
  {
    Child marker({peer(), "pub", "--url", url, "--channel", "FLOW_IN", "--raw", "--count", "1", "--size", "16"});
    ASSERT_EQ(marker.wait_exit(), std::optional<int>(0));
  }
  ASSERT_TRUE(sink_.wait_events(1, kCount + 1));
  EXPECT_EQ(sink_.count(3), extra_before);
  EXPECT_EQ(adapter->statistics().sent, static_cast<std::uint64_t>(kCount));
  adapter->stop();
}

TEST_F(LcmAdapterTest, MalformedEnvelopesCountDecodeErrors) {
  const int port = 7708;
  const std::string url = url_for(port);
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(8, "ENV_IN", HopRole::publisher)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);

  // A valid envelope, then damaged copies of it.
  ::cosmic::envelope e{};
  e.subject = 77;
  e.origin = 42;
  e.sequence = 1;
  e.hop_count = 1;
  e.created_ns = 1;
  e.age_ns = 2;
  e.payload = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  e.payload_size = 10;
  Bytes valid(static_cast<std::size_t>(e.getEncodedSize()));
  ASSERT_EQ(e.encode(valid.data(), 0, static_cast<int>(valid.size())), static_cast<int>(valid.size()));
  auto with_payload_size = [&](std::uint32_t v) {
    Bytes b = valid;
    b[45] = static_cast<std::uint8_t>(v >> 24);
    b[46] = static_cast<std::uint8_t>(v >> 16);
    b[47] = static_cast<std::uint8_t>(v >> 8);
    b[48] = static_cast<std::uint8_t>(v);
    return b;
  };
  std::vector<Bytes> bad;
  bad.push_back(Bytes{1, 2, 3, 4, 5, 6, 7, 8, 9, 10});  // not an envelope at all
  Bytes wrong_hash = valid;
  wrong_hash[0] ^= 0xff;
  bad.push_back(wrong_hash);
  bad.push_back(with_payload_size(static_cast<std::uint32_t>(-5)));  // negative size
  bad.push_back(with_payload_size(100));                             // truncated payload
  bad.push_back(with_payload_size(0x7fffffff));                      // beyond max_message_size
  Bytes trailing = valid;
  trailing.push_back(0);
  bad.push_back(trailing);

  lcm_t* publisher = lcm_create(url.c_str());
  ASSERT_NE(publisher, nullptr);
  for (const auto& b : bad) ASSERT_EQ(lcm_publish(publisher, "ENV_IN", b.data(), static_cast<unsigned>(b.size())), 0);
  ASSERT_EQ(lcm_publish(publisher, "ENV_IN", valid.data(), static_cast<unsigned>(valid.size())), 0);
  lcm_destroy(publisher);

  ASSERT_TRUE(sink_.wait_events(8, 1));
  ASSERT_TRUE(sink_.wait_problems(8, InboundProblem::decode_error, bad.size()));
  EXPECT_EQ(sink_.problems(8, InboundProblem::decode_error), bad.size());
  EXPECT_EQ(adapter->statistics().receive_errors, bad.size());
  const auto events = sink_.events(8);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].header.subject, 77u);
  EXPECT_EQ(events[0].header.origin, 42u);
  EXPECT_EQ(events[0].payload, e.payload);

  // A native envelope publisher that is not us still gets through afterwards.
  Child pub({peer(), "pub", "--url", url, "--channel", "ENV_IN", "--count", "2", "--size", "0", "--origin", "99"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(8, 3));
  EXPECT_TRUE(sink_.events(8)[2].payload.empty());
  adapter->stop();
}

// Issue 9, item 10: the LCM name limit comes from cosmic/transport_limits.hpp (what the
// configuration checks), and a refused name is reported for its channel (Status::refused) while
// the segment carries the rest.
TEST_F(LcmAdapterTest, ANameBeyondTheTransportLimitIsRefusedForItsChannelAlone) {
  auto adapter = make(7710);
  const std::string longest(kLcmMaxChannelName, 'a');
  const std::string too_long(kLcmMaxChannelName + 1, 'b');
  const std::vector<ChannelBinding> bindings{binding(1, longest, HopRole::subscriber),
                                             binding(2, too_long, HopRole::subscriber),
                                             binding(3, "FINE", HopRole::subscriber)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  const Status status = adapter->configure(bindings);
  EXPECT_FALSE(status.ok);
  ASSERT_EQ(status.refused.size(), 1u) << status.error;
  EXPECT_EQ(status.refused[0].channel, 2u);
  EXPECT_EQ(status.refused[0].reason, check_transport_name(SegmentType::lcm, too_long).error().text);
  EXPECT_NE(status.error.find("at most 63 characters"), std::string::npos) << status.error;
  EXPECT_EQ(adapter->send(outbound(1, Bytes{1})), SendStatus::sent);
  EXPECT_EQ(adapter->send(outbound(3, Bytes{1})), SendStatus::sent);
  EXPECT_EQ(adapter->send(outbound(2, Bytes{1})), SendStatus::failed);
  // Without the long name, nothing is refused.
  EXPECT_TRUE(adapter->configure(std::vector<ChannelBinding>{bindings[0], bindings[2]}).ok);
  adapter->stop();
}

// Issue 22, item 12: one configure() contract for every adapter (SegmentAdapter::configure).
// Every problem of one binding names that channel in Status::refused, and the segment carries
// every other binding, the ones it was given before included.
TEST_F(LcmAdapterTest, EveryRefusedBindingIsNamedAndTheRestIsCarried) {
  auto adapter = make(7711);
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector<ChannelBinding>{binding(1, "KEPT", HopRole::subscriber)}).ok);
  const std::vector<ChannelBinding> bindings{
      binding(1, "KEPT", HopRole::subscriber), binding(2, "KEPT", HopRole::subscriber),  // a name taken by id 1
      binding(3, "NEW", HopRole::subscriber), binding(3, "OTHER", HopRole::publisher),   // id 3 under a second name
      binding(4, "", HopRole::subscriber)};
  const Status status = adapter->configure(bindings);
  EXPECT_FALSE(status.ok);
  std::map<ChannelId, std::string> refused;
  for (const ChannelRefusal& r : status.refused) refused.emplace(r.channel, r.reason);
  ASSERT_EQ(refused.size(), 3u) << status.error;
  EXPECT_NE(refused[2].find("already bound by channel id 1"), std::string::npos) << refused[2];
  EXPECT_NE(refused[3].find("already bound as LCM channel 'NEW'"), std::string::npos) << refused[3];
  EXPECT_EQ(refused[4], "the binding has no channel id or name");  // the words of every adapter (BindingPlan)
  EXPECT_EQ(adapter->send(outbound(1, Bytes{1})), SendStatus::sent) << "the channel bound before keeps flowing";
  // A refused channel is not carried in any role: id 3's first (valid) binding is not either.
  EXPECT_EQ(adapter->send(outbound(3, Bytes{1})), SendStatus::failed);
  EXPECT_EQ(adapter->send(outbound(2, Bytes{1})), SendStatus::failed);
  adapter->stop();
}

// The envelope decoder the adapter runs (cosmic/lcm_wire.hpp) against what lcm-gen encodes.
Bytes encoded(const ::cosmic::envelope& e) {
  Bytes out(static_cast<std::size_t>(e.getEncodedSize()));
  EXPECT_EQ(e.encode(out.data(), 0, static_cast<int>(out.size())), static_cast<int>(out.size()));
  return out;
}

TEST(LcmWire, TheFingerprintIsLcmGens) {
  EXPECT_EQ(::cosmic::envelope::getHash(), static_cast<std::int64_t>(kLcmEnvelopeHash));
  ::cosmic::envelope e{};
  EXPECT_EQ(encoded(e).size(), kLcmEnvelopeHeaderSize);
}

TEST(LcmWire, DecodesWhatLcmGenEncodesWithoutCopying) {
  ::cosmic::envelope e{};
  e.subject = -1;  // subject 0xFFFFFFFFFFFFFFFF
  e.origin = INT64_MIN;
  e.sequence = -1;
  e.hop_count = -1;
  e.created_ns = 1'700'000'000'000'000'000;
  e.age_ns = -5;  // the router's ingress check refuses it; the decoder only reports it
  e.payload = {9, 8, 7};
  e.payload_size = 3;
  const Bytes bytes = encoded(e);
  const auto decoded = decode_lcm_envelope(bytes, 3);
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(decoded->header.subject, 0xFFFFFFFFFFFFFFFFull);
  EXPECT_EQ(decoded->header.origin, 0x8000000000000000ull);
  EXPECT_EQ(decoded->header.sequence, 0xFFFFFFFFu);
  EXPECT_EQ(decoded->header.hop_count, 255u);
  EXPECT_EQ(decoded->header.created_ns, 1'700'000'000'000'000'000);
  EXPECT_EQ(decoded->header.age_ns, -5);
  ASSERT_EQ(decoded->payload.size(), 3u);
  EXPECT_EQ(decoded->payload.data(), bytes.data() + kLcmEnvelopeHeaderSize);
  EXPECT_EQ(Bytes(decoded->payload.begin(), decoded->payload.end()), e.payload);

  ::cosmic::envelope empty{};
  const Bytes no_payload = encoded(empty);
  ASSERT_TRUE(decode_lcm_envelope(no_payload, 0).has_value());
  EXPECT_TRUE(decode_lcm_envelope(no_payload, 0)->payload.empty());
}

TEST(LcmWire, EncodesTheHeaderAsLcmGenDoes) {
  ::cosmic::envelope e{};
  e.subject = -2;
  e.origin = INT64_MIN + 7;
  e.sequence = -3;
  e.hop_count = -1;
  e.created_ns = 1'700'000'000'123'456'789;
  e.age_ns = -5;
  e.payload = {1, 2, 3, 4};
  e.payload_size = 4;
  const Bytes reference = encoded(e);
  EventHeader header;
  header.subject = 0xFFFFFFFFFFFFFFFEull;
  header.origin = 0x8000000000000007ull;
  header.sequence = 0xFFFFFFFDu;
  header.hop_count = 255;
  header.created_ns = 1'700'000'000'123'456'789;
  header.age_ns = -5;
  const auto ours = encode_lcm_envelope_header(header, 4);
  Bytes whole(ours.begin(), ours.end());
  whole.insert(whole.end(), e.payload.begin(), e.payload.end());
  EXPECT_EQ(whole, reference);
}

TEST(LcmWire, RefusesAnythingButExactlyOneEnvelopeWithinTheLimit) {
  ::cosmic::envelope e{};
  e.payload = Bytes(10, 0x5a);
  e.payload_size = 10;
  const Bytes valid = encoded(e);
  ASSERT_TRUE(decode_lcm_envelope(valid, 10).has_value());
  EXPECT_FALSE(decode_lcm_envelope(valid, 9).has_value());  // above max_message_size
  auto with_payload_size = [&](std::uint32_t v) {
    Bytes b = valid;
    for (int i = 0; i < 4; ++i) b[kLcmEnvelopePayloadSizeOffset + i] = static_cast<std::uint8_t>(v >> (24 - 8 * i));
    return b;
  };
  Bytes wrong_hash = valid;
  wrong_hash[7] ^= 1;
  Bytes trailing = valid;
  trailing.push_back(0);
  for (const Bytes& bad :
       {Bytes{}, Bytes(valid.begin(), valid.begin() + 48), Bytes(valid.begin(), valid.end() - 1), trailing, wrong_hash,
        with_payload_size(static_cast<std::uint32_t>(-5)), with_payload_size(11), with_payload_size(9),
        with_payload_size(0x7fffffff), with_payload_size(0xffffffff)}) {
    EXPECT_FALSE(decode_lcm_envelope(bad, UINT64_MAX).has_value()) << bad.size();
  }
}

// A segment that only sends has left the group; binding a received channel joins it again, and
// when that join fails (here: the namespace's multicast route is gone) the channel is refused
// with the kernel's reason, the sending one stays bound, and a later configure() joins once the
// route is back.
TEST_F(LcmAdapterTest, AChannelTheSegmentCannotJoinForIsRefusedWithTheReason) {
  const int port = 7713;
  auto adapter = make(port);
  const ChannelBinding out = binding(1, "STAYS_OUT", HopRole::subscriber, LcmEncoding::raw, 5);
  const ChannelBinding in = binding(2, "WANTS_IN", HopRole::publisher, LcmEncoding::raw, 6);
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector{out}).ok);

  ASSERT_EQ(std::system("ip route del 224.0.0.0/4 dev lo"), 0);
  const Status refused = adapter->configure(std::vector{out, in});
  ASSERT_EQ(std::system("ip route add 224.0.0.0/4 dev lo"), 0);
  EXPECT_FALSE(refused.ok);
  ASSERT_EQ(refused.refused.size(), 1u) << refused.error;
  EXPECT_EQ(refused.refused[0].channel, 2u);
  EXPECT_NE(refused.refused[0].reason.find("cannot receive on this segment: joining 239.255.76.67"), std::string::npos)
      << refused.refused[0].reason;
  EXPECT_EQ(adapter->send(outbound(1, own_pattern(1, 16))), SendStatus::sent);  // the sending channel stays

  ASSERT_TRUE(adapter->configure(std::vector{out, in}).ok);
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "WANTS_IN", "--raw", "--count", "2", "--size", "16"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(2, 2));
  adapter->stop();
}

}  // namespace
}  // namespace cosmic::lcm_test
