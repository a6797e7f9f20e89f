// A typed channel's samples in extended CDR (cosmic/cdr_representation.hpp): the encapsulation
// header, the type's checks at make and the padding after the body; the body itself is the walks'
// (cdr_walk.hpp).
#include "cosmic/cdr_representation.hpp"

#include <algorithm>
#include <optional>

#include "cdr_walk.hpp"
#include "cosmic/compact_layout.hpp"
#include "cosmic/dds_encapsulation.hpp"

namespace cosmic {
// The helpers' own namespace: unity builds merge this file with others' anonymous namespaces.
namespace cdr_sample {
namespace {

using cdr_walk::CdrForm;

// Encapsulation identifiers as Cyclone DDS, Fast DDS and RTPS 2.5 (Table 10.3) assign them. XTypes
// 1.3's Table 60 gives CDR2 0x0010 upward instead, an erratum (DDSXTY14-20) no implementation
// followed; dds_encapsulation.cpp knows the same values.
constexpr std::uint16_t kCdrLe = 0x0001;
constexpr std::uint16_t kCdr2Le = 0x0007;
constexpr std::uint16_t kDelimitedCdr2Le = 0x0009;

// The form of a sample's body by its encapsulation identifier; nullopt for what is not a plain
// encoding. The parameter-list encodings (PL_CDR 0x0002/3, PL_CDR2 0x000a/b) are those of mutable
// types: every member behind an id and a length, in any order, optional members left out. A
// channel's type has no member ids, and @mutable types are rare on the networks this gateway joins
// (ROS 2 writes final types): refused rather than guessed at.
std::optional<CdrForm> form_of(std::uint16_t id) {
  const bool little_endian = (id & 1) != 0;
  switch (id & ~1u) {
    case 0x0000:
      return CdrForm{false, false, little_endian};
    case 0x0006:
      return CdrForm{true, false, little_endian};
    case 0x0008:
      return CdrForm{true, true, little_endian};
    default:
      return std::nullopt;
  }
}

// The place of the first conditional field ("mode.dtc"), if any.
std::optional<std::string> conditional_field(const std::vector<TypeField>& fields, const std::string& where);

std::optional<std::string> conditional_in(const FieldType& type, const std::string& where) {
  if (type.kind == FieldType::Kind::record) return conditional_field(type.fields, where);
  for (const FieldType& element : type.element) {
    if (auto found = conditional_in(element, where + "[]")) return found;
  }
  return std::nullopt;
}

std::optional<std::string> conditional_field(const std::vector<TypeField>& fields, const std::string& where) {
  for (const TypeField& f : fields) {
    const std::string place = where.empty() ? f.name : where + "." + f.name;
    if (f.present_when) return place;
    if (auto found = conditional_in(f.type, place)) return found;
  }
  return std::nullopt;
}

CdrForm written_form(DdsRepresentation version, CdrExtensibility extensibility) {
  const bool xcdr2 = version == DdsRepresentation::xcdr2;
  // XCDR1 has no DHEADER: an appendable type is written as a final one.
  return CdrForm{xcdr2, xcdr2 && extensibility == CdrExtensibility::appendable, true};
}

std::uint16_t encapsulation_id(const CdrForm& form) {
  if (!form.xcdr2) return kCdrLe;
  return form.delimited ? kDelimitedCdr2Le : kCdr2Le;
}

Conversion refused(ConversionFault fault) { return Conversion{0, fault, 0}; }

// Whether the bytes after the last member are only padding: exactly what the options announce
// (XTypes 1.3 7.6.3.1.2, Cyclone DDS), or, when they announce none, up to 3 bytes that bring the
// body to a multiple of 4. Fast DDS 2.x announces none but pads the RTPS submessage, and its
// readers hand the padding on as part of the sample.
bool only_padding_after(std::size_t read, std::size_t members, std::size_t announced) {
  if (read == members) return true;
  return announced == 0 && members % 4 == 0 && members - read < 4;
}

}  // namespace
}  // namespace cdr_sample

Result<CdrRepresentation> CdrRepresentation::make(const ChannelType& type, DdsRepresentation write_as,
                                                  CdrExtensibility extensibility) {
  if (const auto problems = check_type(type); !problems.empty()) {
    return Error{"the type is not sound: " + problems.front().where + ": " + problems.front().what};
  }
  if (const auto where = cdr_sample::conditional_field(type.fields, "")) {
    return Error{
        "field " + *where +
        " is conditional (present_when, a DBC message's multiplexed signal): an IDL struct has no such member"};
  }
  CdrRepresentation cdr;
  cdr.type_ = type;
  cdr.write_as_ = write_as;
  cdr.extensibility_ = extensibility;
  const std::uint64_t members = cdr_walk::max_body_size(type.fields, cdr_sample::written_form(write_as, extensibility));
  const std::uint64_t body = members + cdr_walk::padding(members, 4);
  // DHEADERs and lengths are 32-bit; a sample that large is far beyond any transport's anyway.
  if (body > std::uint64_t{UINT32_MAX} - kDdsEncapsulationBytes) {
    return Error{"its largest sample (" + std::to_string(body) + " bytes) is beyond CDR's 32-bit lengths"};
  }
  cdr.max_wire_size_ = kDdsEncapsulationBytes + static_cast<std::size_t>(body);
  cdr.max_compact_size_ = cosmic::max_compact_size(type);
  return cdr;
}

std::string CdrRepresentation::describe() const {
  std::string text = write_as_ == DdsRepresentation::xcdr2 ? "XCDR2" : "XCDR1";
  if (extensibility_ == CdrExtensibility::appendable) text += " appendable";
  return text;
}

Conversion CdrRepresentation::to_compact(std::span<const std::uint8_t> wire,
                                         std::span<std::uint8_t> compact) const noexcept {
  if (compact.size() < max_compact_size_) return cdr_sample::refused(ConversionFault::too_small);
  if (wire.size() < kDdsEncapsulationBytes) return cdr_sample::refused(ConversionFault::malformed);
  const auto form = cdr_sample::form_of(static_cast<std::uint16_t>((wire[0] << 8) | wire[1]));
  if (!form) return cdr_sample::refused(ConversionFault::malformed);
  const std::size_t announced = wire[3] & 3u;  // the options' last two bits: the padding after the body
  const auto body = wire.subspan(kDdsEncapsulationBytes);
  if (announced > body.size()) return cdr_sample::refused(ConversionFault::malformed);
  const auto members = body.first(body.size() - announced);
  const cdr_walk::Walked walk = cdr_walk::read_body(type_.fields, *form, members, compact);
  if (walk.fault != ConversionFault::none) return cdr_sample::refused(walk.fault);
  if (!cdr_sample::only_padding_after(walk.read, members.size(), announced))
    return cdr_sample::refused(ConversionFault::malformed);
  return Conversion{walk.written, ConversionFault::none, 0};
}

Conversion CdrRepresentation::from_compact(std::span<const std::uint8_t> compact,
                                           std::span<std::uint8_t> wire) const noexcept {
  if (wire.size() < max_wire_size_) return cdr_sample::refused(ConversionFault::too_small);
  const cdr_walk::CdrForm form = cdr_sample::written_form(write_as_, extensibility_);
  const cdr_walk::Walked walk = cdr_walk::write_body(type_.fields, form, compact, wire.subspan(kDdsEncapsulationBytes));
  if (walk.fault != ConversionFault::none) return cdr_sample::refused(walk.fault);
  if (walk.read != compact.size())
    return cdr_sample::refused(ConversionFault::malformed);  // bytes after the last field
  const std::size_t body = walk.written;
  const std::size_t pad = cdr_walk::padding(body, 4);
  if (pad > wire.size() - kDdsEncapsulationBytes - body) return cdr_sample::refused(ConversionFault::too_small);
  const std::uint16_t id = cdr_sample::encapsulation_id(form);
  wire[0] = static_cast<std::uint8_t>(id >> 8);
  wire[1] = static_cast<std::uint8_t>(id & 0xFF);
  wire[2] = 0;
  wire[3] = static_cast<std::uint8_t>(pad);
  std::fill_n(wire.data() + kDdsEncapsulationBytes + body, pad, std::uint8_t{0});
  return Conversion{kDdsEncapsulationBytes + body + pad, ConversionFault::none, 0};
}

}  // namespace cosmic
