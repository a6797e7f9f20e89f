// The body of a CDR sample, walked over the channel's type (cdr_walk.hpp). Each walk checks its
// own bounds as it goes, so neither conversion needs check_compact first, and none allocates: the
// type is walked by reference (nesting bounded by kMaxTypeDepth, check_type's bound).
//
// What XTypes 1.3 section 7.4.3 says, as the walks apply it. Alignment is counted from the start of
// the body (after the 4-byte encapsulation header): XCDR1 aligns a primitive to its size, XCDR2 to
// its size but at most 4. Both write a string as a uint32 length counting the NUL, the bytes and
// the NUL; a sequence as a uint32 count and the elements; an array as its elements. XCDR2 puts a
// DHEADER (uint32: the bytes that follow, up to the end of the value) before an array or a sequence
// whose elements are not primitive (rules 9 and 12, whatever the struct's extensibility; booleans
// are primitive, enums and strings are not: OMG issue DDSXTY14-56 asks to relax that for enums, not
// yet done) and, for an appendable type, before every struct. An empty sequence is its count alone:
// its elements' alignment is not applied (Cyclone DDS and Fast CDR align only for an element).
#include "cdr_walk.hpp"

#include <algorithm>
#include <cstring>

#include "cosmic/compact_layout.hpp"

namespace cosmic::cdr_walk {
namespace {

std::size_t alignment(const CdrForm& form, std::size_t size) {
  return form.xcdr2 ? std::min<std::size_t>(size, 4) : size;
}

bool scalar_like(const FieldType& type) {
  return type.kind == FieldType::Kind::scalar || type.kind == FieldType::Kind::enumeration;
}

// Whether XCDR2 writes a collection of `element` without a DHEADER: an IDL primitive. A 32-bit
// enumeration is an IDL enum, any other an IDL integer.
bool primitive(const FieldType& element) {
  if (element.kind == FieldType::Kind::scalar) return true;
  return element.kind == FieldType::Kind::enumeration && scalar_size(element.scalar) != 4;
}

// An array of arrays is one multi-dimensional IDL array (long a[2][3]): its innermost element type
// and how many of them. The compact layout has them in the same order, one after the other.
const FieldType& innermost(const FieldType& array, std::uint64_t& count) {
  const FieldType* type = &array;
  count = 1;
  while (type->kind == FieldType::Kind::array && type->element.size() == 1) {
    count *= type->bound;
    type = &type->element[0];
  }
  return *type;
}

std::uint32_t load_u32(const std::uint8_t* at, bool little_endian) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t{at[little_endian ? i : 3 - i]} << (8 * i);
  return v;
}

void store_u32_le(std::uint32_t v, std::uint8_t* at) {
  for (int i = 0; i < 4; ++i) at[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// The largest body of a type: every string and sequence at its bound. The end of a value only
// grows with where it starts and with its counts, so this is the largest of all events, padding
// included.
class SizeWalk {
 public:
  explicit SizeWalk(CdrForm form) : form_(form) {}

  void record(const std::vector<TypeField>& fields) {
    if (form_.delimited) u32();
    for (const TypeField& f : fields) value(f.type);
  }
  std::uint64_t size() const { return at_; }

 private:
  void value(const FieldType& type) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration:
        return scalars(type.scalar, 1);
      case FieldType::Kind::string:
        u32();
        at_ += std::uint64_t{type.bound} + 1;
        return;
      case FieldType::Kind::array: {
        std::uint64_t count = 0;
        const FieldType& element = innermost(type, count);
        return collection(element, count, false);
      }
      case FieldType::Kind::sequence:
        if (type.element.size() == 1) collection(type.element[0], type.bound, true);
        return;
      case FieldType::Kind::record:
        return record(type.fields);
    }
  }

  void collection(const FieldType& element, std::uint64_t count, bool counted) {
    if (form_.xcdr2 && !primitive(element)) u32();
    if (counted) u32();
    if (scalar_like(element)) return scalars(element.scalar, count);
    for (std::uint64_t i = 0; i < count; ++i) value(element);
  }

  void scalars(ScalarKind kind, std::uint64_t count) {
    const std::size_t size = scalar_size(kind);
    at_ += padding(at_, alignment(form_, size)) + size * count;
  }

  void u32() { scalars(ScalarKind::uint32, 1); }

  CdrForm form_;
  std::uint64_t at_ = 0;
};

// A body into the compact layout. `end_` is where the innermost DHEADER (or the body) ends: no
// value reads past it.
class ReadWalk {
 public:
  ReadWalk(CdrForm form, std::span<const std::uint8_t> body, std::span<std::uint8_t> compact)
      : form_(form), in_(body), end_(body.size()), out_(compact) {}

  bool record(const std::vector<TypeField>& fields) {
    std::size_t outer = 0;
    if (form_.delimited && !open(outer)) return false;
    for (const TypeField& f : fields) {
      if (!value(f.type)) return false;
    }
    // A DHEADER longer than our members: what a newer version of the type appended, skipped.
    return !form_.delimited || close(outer, false);
  }

  std::size_t read() const { return at_; }
  std::size_t written() const { return out_at_; }
  ConversionFault fault() const { return fault_; }

 private:
  bool fail(ConversionFault fault = ConversionFault::malformed) {
    fault_ = fault;
    return false;
  }

  bool value(const FieldType& type) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration:
        return scalars(type.scalar, 1);
      case FieldType::Kind::string:
        return string(type.bound);
      case FieldType::Kind::array: {
        std::uint64_t count = 0;
        const FieldType& element = innermost(type, count);
        return collection(element, count, false);
      }
      case FieldType::Kind::sequence:
        return type.element.size() == 1 ? collection(type.element[0], type.bound, true) : fail();
      case FieldType::Kind::record:
        return record(type.fields);
    }
    return fail();
  }

  bool collection(const FieldType& element, std::uint64_t bound, bool counted) {
    const bool delimited = form_.xcdr2 && !primitive(element);
    std::size_t outer = 0;
    if (delimited && !open(outer)) return false;
    std::uint64_t count = bound;
    if (counted) {
      std::uint32_t n = 0;
      if (!u32(n)) return false;
      if (n > bound) return fail();
      if (!put_u32(n)) return false;
      count = n;
    }
    if (!elements(element, count)) return false;
    // A collection's DHEADER is its size: nothing can have been appended to it.
    return !delimited || close(outer, true);
  }

  bool elements(const FieldType& element, std::uint64_t count) {
    if (scalar_like(element)) return scalars(element.scalar, count);
    for (std::uint64_t i = 0; i < count; ++i) {
      if (!value(element)) return false;
    }
    return true;
  }

  bool scalars(ScalarKind kind, std::uint64_t count) {
    if (count == 0) return true;
    const std::size_t size = scalar_size(kind);
    if (!align(alignment(form_, size))) return false;
    const std::uint64_t bytes = size * count;
    if (bytes > end_ - at_) return fail();
    if (bytes > out_.size() - out_at_) return fail(ConversionFault::too_small);
    const std::uint8_t* from = in_.data() + at_;
    std::uint8_t* to = out_.data() + out_at_;
    if (form_.little_endian || size == 1) {
      std::memcpy(to, from, bytes);
    } else {
      for (std::uint64_t e = 0; e < bytes; e += size) std::reverse_copy(from + e, from + e + size, to + e);
    }
    if (kind == ScalarKind::boolean && std::any_of(to, to + bytes, [](std::uint8_t b) { return b > 1; })) return fail();
    at_ += bytes;
    out_at_ += bytes;
    return true;
  }

  bool string(std::uint32_t bound) {
    std::uint32_t length = 0;
    if (!u32(length)) return false;
    // The length counts the NUL: 0 is no string at all.
    if (length == 0 || length - 1 > bound || length > end_ - at_) return fail();
    if (in_[at_ + length - 1] != 0) return fail();
    if (!put_u32(length - 1)) return false;
    if (length - 1 > out_.size() - out_at_) return fail(ConversionFault::too_small);
    std::memcpy(out_.data() + out_at_, in_.data() + at_, length - 1);
    out_at_ += length - 1;
    at_ += length;
    return true;
  }

  // A DHEADER: the value it announces ends within the one around it.
  bool open(std::size_t& outer) {
    std::uint32_t size = 0;
    if (!u32(size)) return false;
    if (size > end_ - at_) return fail();
    outer = end_;
    end_ = at_ + size;
    return true;
  }

  bool close(std::size_t outer, bool exact) {
    if (exact && at_ != end_) return fail();
    at_ = end_;
    end_ = outer;
    return true;
  }

  bool u32(std::uint32_t& v) {
    if (!align(4)) return false;
    if (end_ - at_ < 4) return fail();
    v = load_u32(in_.data() + at_, form_.little_endian);
    at_ += 4;
    return true;
  }

  bool put_u32(std::uint32_t v) {
    if (out_.size() - out_at_ < 4) return fail(ConversionFault::too_small);
    store_u32_le(v, out_.data() + out_at_);
    out_at_ += 4;
    return true;
  }

  // Padding is skipped whatever it holds: XTypes leaves its content open.
  bool align(std::size_t align) {
    const std::size_t pad = padding(at_, align);
    if (pad > end_ - at_) return fail();
    at_ += pad;
    return true;
  }

  CdrForm form_;
  std::span<const std::uint8_t> in_;
  std::size_t at_ = 0;
  std::size_t end_ = 0;
  std::span<std::uint8_t> out_;
  std::size_t out_at_ = 0;
  ConversionFault fault_ = ConversionFault::none;
};

// The compact layout into a little-endian body. Padding is written as zeros (as Cyclone DDS does),
// so equal events give equal samples.
class WriteWalk {
 public:
  WriteWalk(CdrForm form, std::span<const std::uint8_t> compact, std::span<std::uint8_t> body)
      : form_(form), in_(compact), out_(body) {}

  bool record(const std::vector<TypeField>& fields) {
    std::size_t header = 0;
    if (form_.delimited && !open(header)) return false;
    for (const TypeField& f : fields) {
      if (!value(f.type)) return false;
    }
    if (form_.delimited) close(header);
    return true;
  }

  std::size_t read() const { return in_at_; }
  std::size_t written() const { return at_; }
  ConversionFault fault() const { return fault_; }

 private:
  bool fail(ConversionFault fault = ConversionFault::malformed) {
    fault_ = fault;
    return false;
  }

  bool value(const FieldType& type) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration:
        return scalars(type.scalar, 1);
      case FieldType::Kind::string:
        return string(type.bound);
      case FieldType::Kind::array: {
        std::uint64_t count = 0;
        const FieldType& element = innermost(type, count);
        return collection(element, count, false);
      }
      case FieldType::Kind::sequence:
        return type.element.size() == 1 ? collection(type.element[0], type.bound, true) : fail();
      case FieldType::Kind::record:
        return record(type.fields);
    }
    return fail();
  }

  bool collection(const FieldType& element, std::uint64_t bound, bool counted) {
    const bool delimited = form_.xcdr2 && !primitive(element);
    std::size_t header = 0;
    if (delimited && !open(header)) return false;
    std::uint64_t count = bound;
    if (counted) {
      std::uint32_t n = 0;
      if (!take_u32(n)) return false;
      if (n > bound) return fail();
      if (!put_u32(n)) return false;
      count = n;
    }
    if (!elements(element, count)) return false;
    if (delimited) close(header);
    return true;
  }

  bool elements(const FieldType& element, std::uint64_t count) {
    if (scalar_like(element)) return scalars(element.scalar, count);
    for (std::uint64_t i = 0; i < count; ++i) {
      if (!value(element)) return false;
    }
    return true;
  }

  bool scalars(ScalarKind kind, std::uint64_t count) {
    if (count == 0) return true;
    const std::size_t size = scalar_size(kind);
    const std::uint64_t bytes = size * count;
    if (bytes > in_.size() - in_at_) return fail();
    const std::uint8_t* from = in_.data() + in_at_;
    if (kind == ScalarKind::boolean && std::any_of(from, from + bytes, [](std::uint8_t b) { return b > 1; })) {
      return fail();
    }
    if (!align(alignment(form_, size))) return false;
    if (bytes > out_.size() - at_) return fail(ConversionFault::too_small);
    std::memcpy(out_.data() + at_, from, bytes);  // both little-endian
    in_at_ += bytes;
    at_ += bytes;
    return true;
  }

  bool string(std::uint32_t bound) {
    std::uint32_t size = 0;
    if (!take_u32(size)) return false;
    if (size > bound || size > in_.size() - in_at_) return fail();
    if (!put_u32(size + 1)) return false;
    if (std::uint64_t{size} + 1 > out_.size() - at_) return fail(ConversionFault::too_small);
    std::memcpy(out_.data() + at_, in_.data() + in_at_, size);
    out_[at_ + size] = 0;
    in_at_ += size;
    at_ += std::size_t{size} + 1;
    return true;
  }

  // A DHEADER's place, filled in by close() once the value's size is known.
  bool open(std::size_t& header) {
    if (!put_u32(0)) return false;
    header = at_ - 4;
    return true;
  }

  void close(std::size_t header) { store_u32_le(static_cast<std::uint32_t>(at_ - header - 4), out_.data() + header); }

  bool take_u32(std::uint32_t& v) {
    if (in_.size() - in_at_ < 4) return fail();
    v = load_u32(in_.data() + in_at_, true);
    in_at_ += 4;
    return true;
  }

  bool put_u32(std::uint32_t v) {
    if (!align(4)) return false;
    if (out_.size() - at_ < 4) return fail(ConversionFault::too_small);
    store_u32_le(v, out_.data() + at_);
    at_ += 4;
    return true;
  }

  bool align(std::size_t align) {
    const std::size_t pad = padding(at_, align);
    if (pad > out_.size() - at_) return fail(ConversionFault::too_small);
    std::fill_n(out_.data() + at_, pad, std::uint8_t{0});
    at_ += pad;
    return true;
  }

  CdrForm form_;
  std::span<const std::uint8_t> in_;
  std::size_t in_at_ = 0;
  std::span<std::uint8_t> out_;
  std::size_t at_ = 0;
  ConversionFault fault_ = ConversionFault::none;
};

}  // namespace

std::size_t padding(std::uint64_t at, std::size_t align) {
  return static_cast<std::size_t>((align - at % align) % align);
}

std::uint64_t max_body_size(const std::vector<TypeField>& fields, CdrForm form) {
  SizeWalk walk(form);
  walk.record(fields);
  return walk.size();
}

Walked read_body(const std::vector<TypeField>& fields, CdrForm form, std::span<const std::uint8_t> body,
                 std::span<std::uint8_t> compact) noexcept {
  ReadWalk walk(form, body, compact);
  const bool ok = walk.record(fields);
  return Walked{walk.read(), walk.written(), ok ? ConversionFault::none : walk.fault()};
}

Walked write_body(const std::vector<TypeField>& fields, CdrForm form, std::span<const std::uint8_t> compact,
                  std::span<std::uint8_t> body) noexcept {
  WriteWalk walk(form, compact, body);
  const bool ok = walk.record(fields);
  return Walked{walk.read(), walk.written(), ok ? ConversionFault::none : walk.fault()};
}

}  // namespace cosmic::cdr_walk
