// `cosmicctl gen` for typed channels (issue 35, item 6): a C++ struct per channel's type and its
// events read and written in the compact layout (docs/typed-layout.md). Pure text building.
//
// Files:
//   compact.hpp         the layout's pieces every channel's header uses: compact::Status, ::Result
//                       (a status and the refused field's path, never an exception), ::Writer, ::Reader
//   CHANNEL_type.hpp    per typed channel, in namespace types::CHANNEL:
//                         struct Event            the record; nested records are nested structs and
//                                                 enumerations nested `enum class`es named after their
//                                                 field in CamelCase; fixed arrays std::array,
//                                                 sequences std::vector, strings std::string (each
//                                                 bound a static constexpr FIELD_max_size/_max_length),
//                                                 conditional fields std::optional; units and ranges
//                                                 in comments
//                         max_size                the most bytes an event takes
//                         encode(event, span)     into a caller's buffer: no allocation, noexcept
//                         encode(event, vector&)  resized to the event
//                         decode(bytes, event&)   refuses a short, over-bound or malformed event
// Names that would not compile (a keyword, a clash) get '_' appended.
#pragma once

#include <string>

#include "cosmic/model.hpp"

namespace cosmicctl {

// The header of a typed channel's struct: "CHANNEL_type.hpp".
std::string type_header_name(const cosmic::ChannelSpec& channel);
// The namespace of its struct and functions: "types::CHANNEL".
std::string type_namespace(const cosmic::ChannelSpec& channel);
// The header's text; `channel` has a type.
std::string generate_type_header(const cosmic::ChannelSpec& channel, const std::string& model_file);
// compact.hpp's text.
const char* compact_header();

}  // namespace cosmicctl
