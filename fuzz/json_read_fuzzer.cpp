// Typed events read from JSON (cosmic::JsonEventReader, cosmic/json_event_reader.hpp): a type made
// from the input (scalars, enumerations, strings, arrays, sequences, nested records, conditional
// fields), then the rest of the input as a JSON text of an event. Any bytes: no crash, no read past
// the text or the compact buffer. A text it reads is JSON nlohmann-json parses as an object, gives
// an event check_compact() accepts, and the quiet read agrees; that event written back by
// JsonRepresentation and read again gives the very same compact bytes.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/compact_layout.hpp"
#include "cosmic/json_event_reader.hpp"
#include "cosmic/json_representation.hpp"
#include "fuzz_input.hpp"
#include "fuzz_types.hpp"

using cosmic::fuzz::FuzzInput;
using cosmic::fuzz::require;

namespace {

// An enumeration's integer: odd bytes int8, even uint16 (as fuzz_json_events makes them).
constexpr cosmic::ScalarKind kReadEnumKinds[] = {cosmic::ScalarKind::uint16, cosmic::ScalarKind::int8};
constexpr cosmic::fuzz::TypeShapes kReadShapes{kReadEnumKinds, true};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in(data, size);
  cosmic::ChannelType type;
  type.fields = cosmic::fuzz::make_fields(in, 0, kReadShapes);
  if (!cosmic::check_type(type).empty()) return 0;
  const auto rest = in.bytes(size);
  // The text in a buffer of its own, so a read past its end is one ASan sees.
  const std::vector<char> text(rest.begin(), rest.end());
  const std::string_view json(text.data(), text.size());
  const cosmic::JsonEventReader reader{cosmic::ChannelType(type)};
  std::vector<std::uint8_t> compact(reader.max_compact_size());
  const cosmic::Result<std::size_t> read = reader.read(json, compact);
  std::vector<std::uint8_t> quiet(reader.max_compact_size());
  const std::optional<std::size_t> read_quietly = reader.read_unexplained(json, quiet);
  require(read.ok() == read_quietly.has_value());
  if (!read.ok()) {
    require(!read.error().text.empty());
    return 0;
  }
  compact.resize(read.value());
  quiet.resize(*read_quietly);
  require(quiet == compact);
  require(cosmic::check_compact(type, compact).ok());
  const nlohmann::json parsed = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
  require(!parsed.is_discarded() && parsed.is_object());

  const cosmic::JsonRepresentation writer{cosmic::ChannelType(type)};
  std::string written(writer.max_size(), '\0');
  const auto written_size = writer.write(compact, std::span<char>(written.data(), written.size()));
  require(written_size.has_value());
  written.resize(*written_size);
  std::vector<std::uint8_t> again(reader.max_compact_size());
  const cosmic::Result<std::size_t> reread = reader.read(written, again);
  require(reread.ok());
  again.resize(reread.value());
  // NaN reads back as the one quiet NaN both times, so even its bits agree.
  require(again == compact);
  return 0;
}
