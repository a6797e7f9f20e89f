// Authenticated LCM (issue 36, item 3) over real multicast in a network namespace: what cosmicd
// signs, lcm-logger records whole and the openssl command line verifies; what a host without the
// key sends through liblcm (forged, altered, replayed from lcm-logger's file, too old) never
// becomes an event and is counted, per segment and per channel.
#include <lcm/lcm-cpp.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cosmic/envelope.hpp"
#include "cosmic/lcm_auth.hpp"
#include "cosmic/lcm_wire.hpp"
#include "lcm_adapter_fixture.hpp"

namespace cosmic::lcm_test {
namespace {

Bytes auth_key(std::uint8_t seed) {
  Bytes key(32);
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(seed * 13 + i);
  return key;
}

std::uint64_t transport_count(const SegmentAdapter& adapter, const char* name) {
  return adapter.statistics().transport_counter(name).value_or(~std::uint64_t{0});
}

// The envelope of `payload` as any LCM program would send it (no trailer).
Bytes plain_envelope(const Bytes& payload, std::uint32_t sequence) {
  EventHeader header;
  header.subject = 0x10;
  header.sequence = sequence;
  const auto head = encode_lcm_envelope_header(header, static_cast<std::uint32_t>(payload.size()));
  Bytes out(head.begin(), head.end());
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

// `message` with a trailer signed by `key` at `sent_ns` (a sender holding the key).
Bytes signed_with(const Bytes& key, std::uint64_t sender, const std::string& channel, const Bytes& message,
                  std::int64_t sent_ns) {
  auto signer = LcmAuthSigner::make(key, sender).value();
  LcmAuthTrailer trailer{};
  const std::span<const std::uint8_t> whole(message);
  EXPECT_TRUE(signer.sign(channel, std::span(&whole, 1), sent_ns, trailer));
  Bytes out = message;
  out.insert(out.end(), trailer.begin(), trailer.end());
  return out;
}

std::int64_t wall_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The HMAC-SHA256 the openssl command line computes over `input` with `key`, in hex.
std::string openssl_hmac(const Bytes& key, const Bytes& input, const std::string& dir) {
  const std::string file = dir + "/hmac_input.bin";
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(input.data()), static_cast<std::streamsize>(input.size()));
  const std::string command = "openssl mac -digest SHA256 -macopt hexkey:" + hex(key) + " -in " + file + " HMAC";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return "popen failed";
  char line[256] = {};
  const bool read = std::fgets(line, sizeof line, pipe) != nullptr;
  if (::pclose(pipe) != 0 || !read) return "openssl mac failed";
  std::string out(line);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

class LcmAuthAdapterTest : public LcmAdapterTest {
 protected:
  std::unique_ptr<SegmentAdapter> make_authenticated(int port, const Bytes& key, Nanos window = 1s) {
    LcmAuthSpec auth;
    auth.key_file = "test.key";
    auth.key = SecretKey(key);
    auth.window = window;
    segment_.lcm.auth = std::move(auth);
    return make(port);
  }
};

TEST_F(LcmAuthAdapterTest, SignedEnvelopesCrossAndTheirTrailerIsWhatTheDocumentationSays) {
  const int port = 7791;
  const Bytes key = auth_key(1);
  auto sender = make_authenticated(port, key);
  RecordingSink sender_sink;
  ASSERT_TRUE(sender->start(sender_sink).ok);
  ASSERT_TRUE(sender->configure(std::vector<ChannelBinding>{binding(1, "obstacle", HopRole::subscriber)}).ok);
  auto receiver = make_authenticated(port, key);
  ASSERT_TRUE(receiver->start(sink_).ok);
  ASSERT_TRUE(receiver->configure(std::vector<ChannelBinding>{binding(1, "obstacle", HopRole::publisher)}).ok);

  char dir_template[] = "/tmp/cosmic-lcm-auth-XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  struct RemoveDir {
    std::string path;
    ~RemoveDir() { std::filesystem::remove_all(path); }
  } remove_dir{dir_template};
  const std::string log_path = std::string(dir_template) + "/auth.lcmlog";
  Child logger(
      {cosmic::build_paths::lcm_logger, "-q", "-f", "--flush-interval=10", "--lcm-url=" + url_for(port), log_path});

  // Until lcm-logger has one in its file (it has no readiness signal), then five more.
  std::uint32_t k = 0;
  auto send_next = [&] {
    ++k;
    return sender->send(outbound(1, own_pattern(k, 24), k, 0x10));
  };
  ASSERT_TRUE(
      poll_until([&] { return count_channel(read_lcm_log(log_path), "obstacle") > 0; }, kWait, [&] { send_next(); }))
      << logger.stderr_text();
  const std::uint32_t first = k + 1;
  for (std::uint32_t i = 0; i < 5; ++i) ASSERT_EQ(send_next(), SendStatus::sent);
  ASSERT_TRUE(sink_.wait_events(1, first - 1 + 5));
  std::vector<Bytes> received;
  for (const auto& r : sink_.events(1))
    if (r.header.sequence >= first) received.push_back(r.payload);
  ASSERT_EQ(received.size(), 5u);
  for (std::uint32_t i = 0; i < 5; ++i) EXPECT_EQ(received[i], own_pattern(first + i, 24));
  EXPECT_EQ(transport_count(*receiver, "unauthenticated"), 0u);
  EXPECT_EQ(transport_count(*receiver, "replayed"), 0u);

  // lcm-logger writes its file when a message comes: more of them nudge it.
  ASSERT_TRUE(
      poll_until([&] { return count_channel(read_lcm_log(log_path), "obstacle") >= 6; }, kWait, [&] { send_next(); }));
  ASSERT_TRUE(sink_.wait_events(1, k));
  logger.signal(SIGINT);
  ASSERT_TRUE(logger.wait_exit().has_value()) << logger.stderr_text();
  const auto logged = read_lcm_log(log_path);
  const auto& message = logged.back().data;
  // lcm-gen's decoder reads the envelope and leaves the trailer after it.
  cosmic::envelope decoded;
  ASSERT_EQ(decoded.decode(message.data(), 0, static_cast<int>(message.size())), 49 + 24);
  ASSERT_EQ(message.size(), 49u + 24u + 40u);
  // The tag: HMAC-SHA256 (openssl's) over name length, name, envelope, the trailer's first 24 bytes.
  Bytes input{8, 'o', 'b', 's', 't', 'a', 'c', 'l', 'e'};
  input.insert(input.end(), message.begin(), message.end() - 16);
  const std::string expected = openssl_hmac(key, input, dir_template);
  EXPECT_EQ(hex(Bytes(message.end() - 16, message.end())), expected.substr(0, 32));

  // The recording played back as it was: a replay, whatever the sender's window.
  lcm::LCM player(url_for(port));
  ASSERT_TRUE(player.good());
  player.publish("obstacle", message.data(), static_cast<unsigned>(message.size()));
  ASSERT_TRUE(sink_.wait_problems(1, InboundProblem::replayed, 1));
  EXPECT_EQ(transport_count(*receiver, "replayed"), 1u);
  EXPECT_EQ(sink_.count(1), k);
  receiver->stop();
  sender->stop();
}

TEST_F(LcmAuthAdapterTest, WhatAHostWithoutTheKeySendsNeverBecomesAnEvent) {
  const int port = 7792;
  const Bytes key = auth_key(1);
  auto receiver = make_authenticated(port, key, 500ms);
  ASSERT_TRUE(receiver->start(sink_).ok);
  ASSERT_TRUE(receiver->configure(std::vector<ChannelBinding>{binding(1, "obstacle", HopRole::publisher)}).ok);
  lcm::LCM host(url_for(port));
  ASSERT_TRUE(host.good());
  auto publish = [&](const Bytes& bytes) {
    host.publish("obstacle", bytes.data(), static_cast<unsigned>(bytes.size()));
  };

  // An authentic message first: the path works, and it is the one event of this test.
  const Bytes authentic = signed_with(key, 0xA, "obstacle", plain_envelope(own_pattern(1, 16), 1), wall_now_ns());
  publish(authentic);
  ASSERT_TRUE(sink_.wait_events(1, 1));

  publish(plain_envelope(own_pattern(2, 16), 2));  // an LCM program's envelope, no trailer
  Bytes altered = signed_with(key, 0xA, "obstacle", plain_envelope(own_pattern(3, 16), 3), wall_now_ns());
  altered[49] ^= 0x80;  // the first payload byte: the obstacle moved
  publish(altered);
  publish(signed_with(auth_key(2), 0xB, "obstacle", plain_envelope(own_pattern(4, 16), 4), wall_now_ns()));
  publish(signed_with(key, 0xA, "drive", plain_envelope(own_pattern(5, 16), 5), wall_now_ns()));  // another channel's
  ASSERT_TRUE(sink_.wait_problems(1, InboundProblem::unauthenticated, 4));

  publish(authentic);  // the same datagram again
  publish(signed_with(key, 0xC, "obstacle", plain_envelope(own_pattern(6, 16), 6), wall_now_ns() - 5'000'000'000));
  publish(signed_with(key, 0xD, "obstacle", plain_envelope(own_pattern(7, 16), 7), wall_now_ns() + 5'000'000'000));
  ASSERT_TRUE(sink_.wait_problems(1, InboundProblem::replayed, 3));

  // A last authentic one (a sender of its own: each signed_with() numbers from 1): everything
  // before it has been read and judged.
  publish(signed_with(key, 0xE, "obstacle", plain_envelope(own_pattern(8, 16), 8), wall_now_ns()));
  ASSERT_TRUE(sink_.wait_events(1, 2));
  const auto events = sink_.events(1);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].payload, own_pattern(1, 16));
  EXPECT_EQ(events[1].payload, own_pattern(8, 16));
  EXPECT_EQ(sink_.problems(1, InboundProblem::unauthenticated), 4u);
  EXPECT_EQ(sink_.problems(1, InboundProblem::replayed), 3u);
  EXPECT_EQ(sink_.problems(1, InboundProblem::decode_error), 0u);
  EXPECT_EQ(transport_count(*receiver, "unauthenticated"), 4u);
  EXPECT_EQ(transport_count(*receiver, "replayed"), 3u);
  receiver->stop();
}

TEST_F(LcmAuthAdapterTest, RawChannelsCannotBeBoundOnAnAuthenticatedSegment) {
  auto adapter = make_authenticated(7793, auth_key(1));
  ASSERT_TRUE(adapter->start(sink_).ok);
  const Status status = adapter->configure(std::vector<ChannelBinding>{
      binding(1, "obstacle", HopRole::publisher), binding(2, "scan", HopRole::publisher, LcmEncoding::raw)});
  ASSERT_FALSE(status.ok);
  EXPECT_NE(status.error.find("a raw LCM message cannot carry the authentication trailer"), std::string::npos)
      << status.error;
  EXPECT_EQ(transport_count(*adapter, "unauthenticated"), 0u);
  adapter->stop();
}

TEST_F(LcmAuthAdapterTest, ASegmentWithoutAuthReportsNoAuthenticationCounters) {
  auto adapter = make(7794);
  ASSERT_TRUE(adapter->start(sink_).ok);
  EXPECT_FALSE(adapter->statistics().transport_counter("unauthenticated"));
  adapter->stop();
}

}  // namespace
}  // namespace cosmic::lcm_test
