// What the JSON writer (cosmic/json_representation.hpp) and reader (cosmic/json_event_reader.hpp)
// of typed events share, so the two agree on one reading of the type: the bound of a written
// event's text, which field selects each conditional field, and what valid UTF-8 is. Internal to
// lib/core; pure functions, any thread.
#pragma once

#include <cstddef>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "cosmic/channel_type.hpp"

namespace cosmic::json_text {

// The most bytes JsonRepresentation::write() needs for a record of `fields`.
std::size_t max_record_size(const std::vector<TypeField>& fields);

// A conditional field -> the index of its selector in the same record, for every record of the
// fields (nested records and element types included). The pointers are into `fields`.
using Selectors = std::unordered_map<const TypeField*, std::size_t>;
void index_selectors(const std::vector<TypeField>& fields, Selectors& out);

// The length of the valid UTF-8 sequence starting at `text` (1..4), or 0 when it is not one
// (overlong forms, surrogates and code points beyond U+10FFFF are not).
std::size_t utf8_sequence(std::string_view text);

}  // namespace cosmic::json_text
