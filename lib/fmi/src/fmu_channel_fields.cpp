// Mapped fields in and out of compact events (cosmic/fmu_channel_fields.hpp).
#include "cosmic/fmu_channel_fields.hpp"

#include <algorithm>
#include <cstring>

#include "cosmic/compact_layout.hpp"

namespace cosmic::fmi {
namespace {

std::uint32_t read_count(std::span<const std::uint8_t> bytes, std::size_t at) {
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + at, sizeof n);  // the layout is little-endian, as this host
  return n;
}

// Walks `type` in `bytes` from `at`, taking the values of the fields `slots_of` names; false when
// the bytes end inside it.
class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, const std::vector<const TypeField*>& fields,
         std::vector<FieldValue>& slots)
      : bytes_(bytes), fields_(fields), slots_(slots) {}

  // A record's fields. A conditional field (present_when) its selector does not select keeps its
  // place (zero bits) but is absent: its slots say so, and the FMU's variable keeps its value.
  bool fields(const std::vector<TypeField>& list) {
    selectors_.clear();
    for (const TypeField& f : list) {
      const bool is_scalar = f.type.kind == FieldType::Kind::scalar || f.type.kind == FieldType::Kind::enumeration;
      const std::size_t at = at_;
      if (!field(f.type, &f)) return false;
      if (is_scalar) selectors_.emplace_back(&f, read_scalar(f.type.scalar, bytes_.data() + at));
      if (f.present_when && !selected(*f.present_when)) mark_absent(&f);
    }
    return true;
  }
  std::size_t at() const { return at_; }

 private:
  bool field(const FieldType& type, const TypeField* named) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration: {
        const std::size_t n = scalar_size(type.scalar);
        if (bytes_.size() - at_ < n) return false;
        for_slots(named, [&](FieldValue& slot) { slot.scalar = read_scalar(type.scalar, bytes_.data() + at_); });
        at_ += n;
        return true;
      }
      case FieldType::Kind::string: {
        if (bytes_.size() - at_ < 4) return false;
        const std::uint32_t n = read_count(bytes_, at_);
        if (bytes_.size() - at_ - 4 < n) return false;
        for_slots(named, [&](FieldValue& slot) {
          slot.text.assign(reinterpret_cast<const char*>(bytes_.data() + at_ + 4), n);
        });
        at_ += 4 + n;
        return true;
      }
      case FieldType::Kind::array:
        return elements(type.element.at(0), type.bound);
      case FieldType::Kind::sequence: {
        if (bytes_.size() - at_ < 4) return false;
        const std::uint32_t n = read_count(bytes_, at_);
        at_ += 4;
        return elements(type.element.at(0), n);
      }
      case FieldType::Kind::record: {
        auto outer = std::move(selectors_);  // a nested record selects among its own fields
        const bool ok = fields(type.fields);
        selectors_ = std::move(outer);
        return ok;
      }
    }
    return false;
  }
  // Elements are never mapped: skipped, in one stride when their size does not vary.
  bool elements(const FieldType& element, std::uint32_t count) {
    if (const auto size = fixed_compact_size(element)) {
      if ((bytes_.size() - at_) / std::max<std::size_t>(*size, 1) < count && *size != 0) return false;
      at_ += *size * count;
      return true;
    }
    for (std::uint32_t i = 0; i < count; ++i)
      if (!field(element, nullptr)) return false;
    return true;
  }
  // Every slot that maps `named` (two variables may take one field) gets its value.
  template <typename Assign>
  void for_slots(const TypeField* named, Assign assign) {
    if (named == nullptr) return;
    for (std::size_t i = 0; i < fields_.size(); ++i)
      if (fields_[i] == named) assign(slots_[i]);
  }
  bool selected(const FieldPresence& presence) const {
    for (const auto& [f, value] : selectors_) {
      if (f->name != presence.selector) continue;
      const std::int64_t v =
          is_signed_integer(f->type.scalar) ? value.integer : static_cast<std::int64_t>(value.unsigned_integer);
      return v == presence.value;
    }
    return true;  // no such selector in this record: the configuration's type check rules it out
  }
  void mark_absent(const TypeField* f) {
    for_slots(f, [](FieldValue& slot) { slot.present = false; });
  }

  std::span<const std::uint8_t> bytes_;
  const std::vector<const TypeField*>& fields_;
  std::vector<FieldValue>& slots_;
  std::size_t at_ = 0;
  std::vector<std::pair<const TypeField*, ScalarValue>> selectors_;  // this record's scalars read so far
};

void append_count(std::vector<std::uint8_t>& out, std::uint32_t n) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&n);
  out.insert(out.end(), p, p + sizeof n);
}

// The zero value of a field nobody sets: zero bits, empty strings and sequences.
void append_zero(const FieldType& type, std::vector<std::uint8_t>& out) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
    case FieldType::Kind::enumeration:
      out.insert(out.end(), scalar_size(type.scalar), 0);
      return;
    case FieldType::Kind::string:
    case FieldType::Kind::sequence:
      append_count(out, 0);
      return;
    case FieldType::Kind::array:
      for (std::uint32_t i = 0; i < type.bound; ++i) append_zero(type.element.at(0), out);
      return;
    case FieldType::Kind::record:
      for (const TypeField& f : type.fields) append_zero(f.type, out);
      return;
  }
}

void append_fields(const std::vector<TypeField>& list, const std::vector<const TypeField*>& fields,
                   const std::vector<FieldValue>& slots, std::vector<std::uint8_t>& out) {
  for (const TypeField& f : list) {
    const auto it = std::find(fields.begin(), fields.end(), &f);
    if (f.type.kind == FieldType::Kind::record) {
      append_fields(f.type.fields, fields, slots, out);
    } else if (it == fields.end()) {
      append_zero(f.type, out);
    } else {
      const FieldValue& value = slots[static_cast<std::size_t>(it - fields.begin())];
      if (f.type.kind == FieldType::Kind::string) {
        const std::size_t n = std::min<std::size_t>(value.text.size(), f.type.bound);
        append_count(out, static_cast<std::uint32_t>(n));
        out.insert(out.end(), value.text.begin(), value.text.begin() + static_cast<std::ptrdiff_t>(n));
      } else {
        const std::size_t at = out.size();
        out.resize(at + scalar_size(f.type.scalar));
        write_scalar(f.type.scalar, value.scalar, out.data() + at);
      }
    }
  }
}

}  // namespace

const TypeField* field_at_path(const std::vector<TypeField>& fields, std::string_view path) {
  const std::size_t dot = path.find('.');
  const std::string_view head = path.substr(0, dot);
  for (const TypeField& f : fields) {
    if (f.name != head) continue;
    if (dot == std::string_view::npos) return &f;
    return f.type.kind == FieldType::Kind::record ? field_at_path(f.type.fields, path.substr(dot + 1)) : nullptr;
  }
  return nullptr;
}

Result<ChannelFields> ChannelFields::make(const ChannelType& type, const std::vector<std::string>& paths) {
  ChannelFields out(type);
  for (const auto& path : paths) {
    const TypeField* f = field_at_path(type.fields, path);
    if (f == nullptr) return Error{"the type has no field '" + path + "'"};
    const auto kind = f->type.kind;
    if (kind != FieldType::Kind::scalar && kind != FieldType::Kind::enumeration && kind != FieldType::Kind::string)
      return Error{"field '" + path + "' is " + describe(f->type) +
                   ": only scalars, enumerations and strings are mapped"};
    out.slot_fields_.push_back(f);
  }
  return out;
}

Result<void> ChannelFields::read(std::span<const std::uint8_t> event, std::vector<FieldValue>& slots) const {
  if (auto sound = check_compact(*type_, event); !sound) return sound.error();
  slots.resize(slot_fields_.size());
  for (FieldValue& slot : slots) slot.present = true;
  Reader reader(event, slot_fields_, slots);
  if (!reader.fields(type_->fields)) return Error{"the event ends inside a field"};
  return {};
}

void ChannelFields::write(const std::vector<FieldValue>& slots, std::vector<std::uint8_t>& event) const {
  event.clear();
  append_fields(type_->fields, slot_fields_, slots, event);
}

}  // namespace cosmic::fmi
