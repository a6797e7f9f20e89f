// What DDS Security's cryptography adds to one DDS hop on this machine, measured through Fast DDS
// itself (issue 36, item 5; `cosmicctl calibrate`, docs/security.md): two participants of this
// process, each with its own identity of a throw-away PKI (cosmic/ephemeral_pki.hpp), send samples
// of the hop's size one way, first with authentication and access control only (the governance's
// protection `none`), then protected as the segment's governance asks (`sign` or `encrypt`). The
// difference per quantile of the one-way latencies (writer's write to reader's listener, steady
// clock) is what the plugins' transformations cost: encoding at the writer and decoding at the
// reader, the two ends of a hop. Samples go over Fast DDS's shared-memory transport with
// intra-process delivery off (which would pass them around the cryptography), so no datagram leaves
// the process and no network, nor the operator's keys, is involved.
//
// Threads: blocks its caller for the two runs (seconds); Fast DDS's own threads deliver. Sets Fast
// DDS's process-wide library settings for the duration and restores them: call it where no other
// participant of the process is being made (cosmicctl).
#pragma once

#include <cstddef>
#include <cstdint>

#include <fastrtps/attributes/LibrarySettingsAttributes.h>

#include "cosmic/auth_timing.hpp"
#include "cosmic/dds_permissions.hpp"
#include "cosmic/result.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

struct DdsSecurityTimingRequest {
  DdsProtection protection = DdsProtection::encrypt;
  std::size_t payload_bytes = 64;  // the serialized sample's body (the hop's largest message)
  // A domain no participant of this host uses: its shared-memory ports are the participants' own.
  std::uint32_t domain = 232;
  std::size_t samples = 4000;  // measured per run, after a warm-up
  double rate_hz = 2000;
  Nanos match_timeout = std::chrono::seconds(10);  // authentication and matching of the pair
};

struct DdsSecurityTiming {
  DdsProtection protection = DdsProtection::encrypt;
  AuthTiming plain;       // one-way latency, authenticated, nothing protected
  AuthTiming protected_;  // one-way latency, protected as asked
  // Protected minus plain, quantile by quantile, never below 0 nor below the quantile before: the cost.
  AuthTiming added;
  double plain_cpu_us = 0;      // this process's CPU time per sample (both ends), plain run
  double protected_cpu_us = 0;  // and protected run
  std::size_t lost = 0;         // samples of either run that never arrived
};

// While it lives, Fast DDS does not hand samples between participants of this process directly
// (intra-process delivery, past the transports and so past the cryptography): they take the
// transport as between two hosts, protected as the governance asks. Process-wide (Fast DDS's
// library settings), restored at destruction; made and destroyed on one thread, with no
// participant being created meanwhile.
class IntraProcessDeliveryOff {
 public:
  IntraProcessDeliveryOff();
  ~IntraProcessDeliveryOff();
  IntraProcessDeliveryOff(const IntraProcessDeliveryOff&) = delete;
  IntraProcessDeliveryOff& operator=(const IntraProcessDeliveryOff&) = delete;

 private:
  eprosima::fastrtps::LibrarySettingsAttributes saved_;
};

// Runs the two measurements. Fails, with the reason, when the PKI or documents cannot be made, a
// participant cannot be created, or the pair does not authenticate and match within the timeout.
Result<DdsSecurityTiming> time_dds_security(const DdsSecurityTimingRequest& request);

}  // namespace cosmic
