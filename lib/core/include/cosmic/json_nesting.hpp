// A guard for parsers of untrusted JSON (control requests, federation announcements): nlohmann's
// parser recurses once per nesting level, so a hostile text could exhaust the stack.
#pragma once

#include <string_view>

namespace cosmic {

// True when no array or object in `text` nests deeper than `limit`, judged without parsing (a
// linear scan that skips strings) so a hostile text never reaches a recursive walk.
bool json_nesting_within(std::string_view text, int limit);

}  // namespace cosmic
