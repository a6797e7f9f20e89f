// LCM type files as a typed channel's `type: {lcm: FILE, ...}` names them (cosmic::parse_lcm_types,
// cosmic/lcm_types.hpp): any bytes end in structs and/or located errors, never a crash. Every struct
// of a file without errors keeps the limits, has its fingerprint (or a nested struct missing or
// containing itself) and a type that is refused with located errors or sound; the structs written
// back as LCM text read back equal, with the same fingerprints.
#include <cstdint>
#include <string>
#include <string_view>

#include "cosmic/lcm_types.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

int line_count(std::string_view text) {
  int lines = 1;
  for (const char c : text) lines += c == '\n' ? 1 : 0;
  return lines;
}

// One package per text: structs of other packages are left out of the round trip.
std::string to_lcm(const cosmic::LcmTypeFile& file, const std::string& package) {
  std::string text = package.empty() ? "" : "package " + package + ";\n";
  for (const auto& s : file.structs) {
    if (s.package != package) continue;
    text += "struct " + s.name + " {\n";
    for (const auto& m : s.members) {
      text += "  " + m.type + " " + m.name;
      for (const auto& d : m.dimensions) text += "[" + d.size + "]";
      text += ";\n";
    }
    for (const auto& c : s.constants) text += "  const " + c.type + " " + c.name + " = " + c.value + ";\n";
    text += "}\n";
  }
  return text;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const cosmic::LcmTypeFile file = cosmic::parse_lcm_types(text);
  const int lines = line_count(text);
  for (const auto& e : file.errors) require(!e.message.empty() && (e.line == 0 || (e.line <= lines && e.column >= 1)));
  if (!file.ok()) return 0;
  require(file.structs.size() <= cosmic::kLcmMaxStructs);
  for (const auto& s : file.structs) {
    require(!s.name.empty() && s.members.size() <= cosmic::kLcmMaxMembers);
    for (const auto& m : s.members) require(m.dimensions.size() <= cosmic::kLcmMaxDimensions);
    (void)cosmic::lcm_fingerprint(file, s);
    const cosmic::LcmChannelType typed = cosmic::lcm_channel_type(file, s);
    if (typed.ok()) require(cosmic::check_type(typed.type).empty());
    for (const auto& e : typed.errors) require(!e.message.empty());
  }
  const std::string package = file.structs.empty() ? "" : file.structs.front().package;
  const cosmic::LcmTypeFile again = cosmic::parse_lcm_types(to_lcm(file, package));
  require(again.ok());
  std::size_t i = 0;
  for (const auto& s : file.structs) {
    if (s.package != package) continue;
    require(i < again.structs.size());
    const auto& t = again.structs[i++];
    require(t.full_name() == s.full_name() && t.members.size() == s.members.size());
    require(cosmic::lcm_base_hash(t) == cosmic::lcm_base_hash(s));
  }
  require(i == again.structs.size());
  return 0;
}
