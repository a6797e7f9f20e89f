// A typed channel's hop on DDS as the serialized sample of an IDL struct (issue 35, "each hop in
// its network's own form"): the channel's type (cosmic/channel_type.hpp) read as that struct, its
// samples in extended CDR (DDS-XTypes 1.3 section 7.4.3) converted to and from the compact layout
// (cosmic/compact_layout.hpp). A unit of its own (its fuzz target: fuzz_cdr), checked against
// Cyclone DDS's serializer both ways (tests/integration/dds/cyclone/cdr_check_test.sh).
//
// The type as IDL: the fields in order are the struct's members; a nested record is a nested
// struct; bool is boolean (1 byte); intN and uintN are the IDL integers of that size (int8, uint8,
// short, ..., unsigned long long); float32 and float64 are float and double; an enumeration whose
// underlying integer is 32 bits (int32, uint32: what an IDL or ROS 2 enum reads as) is an IDL enum
// (4 bytes), any other is the IDL integer of its size (ROS 2 and DBC enumerations are such
// integers with named constants); a string is a bounded string; a fixed array is an array, an
// array of arrays one multi-dimensional array (long a[2][3]); a sequence is a bounded sequence.
// Every nested struct has the extensibility the whole type has. A conditional field (present_when,
// a DBC message's multiplexed signals) has no CDR form: make() refuses it.
//
// Reading takes any plain encoding, whatever the hop writes: XCDR1 (CDR_BE, CDR_LE; an appendable
// type in XCDR1 is serialized as a final one), XCDR2 of a final type (CDR2_BE, CDR2_LE) and of an
// appendable one (D_CDR2_BE, D_CDR2_LE, with a DHEADER before every struct: members a newer version
// of the type appended after ours are skipped). So a hop that writes XCDR2 forwards what an XCDR1
// publisher wrote: transcoding. Parameter-list encodings (PL_CDR, PL_CDR2: mutable types) are
// refused. Writing is the configured version, little-endian, the sample padded to a multiple of 4
// with the padding count in the options (XTypes 1.3 7.6.3.1.2), as Cyclone DDS writes.
//
// Built once per binding (make(), on the control thread), then only read: to_compact() runs on the
// ingress thread that read the hop's network, from_compact() on the egress lane of the hop's
// segment; both run on any number of threads at once, allocate nothing and never throw.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "cosmic/channel_type.hpp"
#include "cosmic/model.hpp"
#include "cosmic/representation.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// The IDL struct's extensibility (@final, @appendable). Mutable types are not supported: their
// parameter-list encodings give every member an id the channel's type does not have.
enum class CdrExtensibility : std::uint8_t { final_type, appendable };

class CdrRepresentation final : public Representation {
 public:
  // The representation of `type` written as `write_as`; else why not (a conditional field, a type
  // check_type() refuses, a largest sample beyond CDR's 32-bit lengths).
  static Result<CdrRepresentation> make(const ChannelType& type, DdsRepresentation write_as,
                                        CdrExtensibility extensibility);

  // "XCDR1", "XCDR2", "XCDR2 appendable".
  std::string describe() const override;
  // The largest sample from_compact() writes: encapsulation header, DHEADERs, alignment and the
  // final padding included, every string and sequence at its bound. A sample another writer sends
  // may be longer: a newer appendable version's members, a writer's alignment padding.
  std::size_t max_wire_size() const noexcept override { return max_wire_size_; }
  std::size_t max_compact_size() const noexcept override { return max_compact_size_; }

  // A sample (encapsulation header first) as one event. Faults: malformed (not a CDR encoding of
  // the type: cut short, a count or string over its bound, a string without its NUL, a bool other
  // than 0 or 1, a DHEADER shorter than our members or not the size of its collection, bytes after
  // the last member beyond the padding to a multiple of 4, a parameter-list encoding);
  // too_small (`compact` is shorter than max_compact_size()).
  Conversion to_compact(std::span<const std::uint8_t> wire, std::span<std::uint8_t> compact) const noexcept override;
  // An event as a sample in the configured version. Faults: too_small (`wire` is shorter than
  // max_wire_size()); malformed (`compact` is not an event of the type: what check_compact refuses).
  Conversion from_compact(std::span<const std::uint8_t> compact, std::span<std::uint8_t> wire) const noexcept override;

 private:
  CdrRepresentation() = default;

  ChannelType type_;
  DdsRepresentation write_as_ = DdsRepresentation::xcdr1;
  CdrExtensibility extensibility_ = CdrExtensibility::final_type;
  std::size_t max_wire_size_ = 0;
  std::size_t max_compact_size_ = 0;
};

}  // namespace cosmic
