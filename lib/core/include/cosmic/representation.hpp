// A typed channel's representation on one hop (issue 35, "each hop in its network's own form"): how
// the hop's messages carry an event, and the conversion between them and the compact layout, the
// one form the gateway itself gives a typed event (cosmic/compact_layout.hpp). Each network's form
// is a unit of its own behind this interface (the compact layout itself on the gateway's own
// envelopes and frames, a DBC message's frame, JSON, the LCM type's encoding, CDR), each with its
// fuzz target; the router converts through it and the transports carry the bytes it gives them.
//
// Built once per binding (at bind or reload, on the control thread), then only read: to_compact()
// runs on the ingress thread that read the hop's network, from_compact() on the egress lane of the
// hop's segment; both run on any number of threads at once, allocate nothing and never throw.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace cosmic {

class E2eProtection;

// Why a conversion produced nothing.
enum class ConversionFault : std::uint8_t {
  none,
  malformed,     // the input is not one event in its form (cut short, a count over its bound, trailing bytes, ...)
  out_of_range,  // a value the target cannot hold, under the drop policy
  too_small,     // the output buffer is smaller than the representation's bound says it needs
};

struct Conversion {
  std::size_t size = 0;  // bytes written (0 unless fault is none)
  ConversionFault fault = ConversionFault::none;
  std::uint32_t out_of_range = 0;  // values that did not fit: saturated, or why it was dropped
  bool ok() const { return fault == ConversionFault::none; }
};

class Representation {
 public:
  virtual ~Representation() = default;

  // How `cosmicctl channel` and errors name it: "compact", "DBC frame 0x3A0 BodyStatus", "JSON",
  // "LCM exlcm.pose_t", "XCDR2".
  virtual std::string describe() const = 0;
  // The most bytes one message of the hop takes, and the most one event in the compact layout takes.
  virtual std::size_t max_wire_size() const noexcept = 0;
  virtual std::size_t max_compact_size() const noexcept = 0;
  // The end-to-end protection the hop's messages carry (a DBC message's counter and CRC;
  // cosmic/e2e_protection.hpp), or null. The router checks it on what the hop brings in, before
  // to_compact(), and writes it on what from_compact() made, with the counters it keeps per hop.
  virtual const E2eProtection* e2e() const noexcept { return nullptr; }
  // The fields whose declared range the form holds only in part, its values beyond saturated at
  // the form's limit (a signal gateway's narrower signal under on_range: saturate), or empty.
  // Admission degrades the channel with it (check "range").
  virtual std::string narrowed() const { return {}; }

  // One received message of the hop as one event in the compact layout, into `compact` (at least
  // max_compact_size() bytes).
  virtual Conversion to_compact(std::span<const std::uint8_t> wire, std::span<std::uint8_t> compact) const noexcept = 0;
  // One event in the compact layout (check_compact has accepted it: the router checks every event
  // it takes in) as one message of the hop, into `wire` (at least max_wire_size() bytes).
  virtual Conversion from_compact(std::span<const std::uint8_t> compact,
                                  std::span<std::uint8_t> wire) const noexcept = 0;

 protected:
  Representation() = default;
  Representation(const Representation&) = default;
  Representation& operator=(const Representation&) = default;
};

}  // namespace cosmic
