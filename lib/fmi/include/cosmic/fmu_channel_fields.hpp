// The fields an FMU maps in one typed channel's events (compact layout, docs/typed-layout.md): read
// out of an input channel's event before a step, written into a whole output event after it.
//
// Built once per channel when the runner starts; read() and write() then allocate nothing once the
// caller's buffers have grown (strings aside). Pure; no I/O, never throw; one thread per object.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/fmi_values.hpp"
#include "cosmic/result.hpp"

namespace cosmic::fmi {

// The field at a dotted path through nested records ("pose.v"); null when there is none. The
// configuration checks mappings with it, ChannelFields finds them with it.
const TypeField* field_at_path(const std::vector<TypeField>& fields, std::string_view path);

class ChannelFields {
 public:
  // `paths` are dotted field paths into `type` (as the configuration checked them): each must name a
  // scalar, enumeration or string field. Slot i of read()/write() is paths[i].
  static Result<ChannelFields> make(const ChannelType& type, const std::vector<std::string>& paths);

  // The mapped fields' values out of `event`, which must be one event of the type (check_compact);
  // an error names what is wrong with it.
  Result<void> read(std::span<const std::uint8_t> event, std::vector<FieldValue>& slots) const;
  // A whole event from the slots' values: fields nobody maps (conditional ones) are zero, a string
  // longer than its bound is cut to it.
  void write(const std::vector<FieldValue>& slots, std::vector<std::uint8_t>& event) const;

  const TypeField& field(std::size_t slot) const { return *slot_fields_[slot]; }
  std::size_t size() const { return slot_fields_.size(); }

 private:
  explicit ChannelFields(const ChannelType& type) : type_(&type) {}
  const ChannelType* type_;                    // the configuration's; outlives this
  std::vector<const TypeField*> slot_fields_;  // slot -> field
};

}  // namespace cosmic::fmi
