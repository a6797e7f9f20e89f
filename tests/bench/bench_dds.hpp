// The Fast DDS side of cosmic-bench-peer (dds-pub, dds-sub; bench_peer.cpp's header comment says
// what they do). A topic is either cosmic::Envelope (cosmicd's envelope topics cosmic/<channel>)
// or, with a native type name, a raw type of the peer's own whose samples are the bytes it writes:
// a CDR encapsulation header 00 01 00 00 (CDR_LE, XCDR1) followed by the event's payload.
#pragma once

#include <cstdint>
#include <string>

namespace cosmic_bench {

struct DdsOptions {
  unsigned domain = 0;
  std::string topic;
  std::string native_type;  // empty: cosmic::Envelope; otherwise the raw type announced as this name
  // A secure participant (DDS Security, docs/security.md) when `identity` is set: the PKI in
  // `pki` laid out as tests/support/make_test_pki.sh makes it (identity_ca.pem, IDENTITY_cert.pem,
  // IDENTITY_key.pem, permissions_ca.pem, permissions.p7s), governed by `governance` (default
  // PKI/governance.p7s).
  std::string pki;
  std::string identity;
  std::string governance;
  std::uint64_t count = 0;
  std::uint64_t size = 64;
  double rate = 0;
  double max_rate = 0;  // 0: catch up after a stall at full speed
  std::uint64_t warmup = 200;
  int keep_last = 0;  // the writer's or reader's history: 0 KEEP_ALL, else KEEP_LAST of this depth
  // dds-pub: Fast DDS's own heartbeat period (3 s) instead of the peer's 50 ms, as a writer
  // with default QoS announces its samples (scripts/bench's relay-rates section).
  bool default_heartbeat = false;
  bool wait_go = false;
  double match_timeout = 20;
  double stall = 5;
  double timeout = 60;
  double idle = 1.5;
  std::string dump;
};

int dds_pub(const DdsOptions& o);
int dds_sub(const DdsOptions& o);

}  // namespace cosmic_bench
