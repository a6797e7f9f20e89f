// Renders admission reports for people (a table) and for programs (the JSON contract of
// `cosmicctl check --json`, documented in docs/control-protocol.md). Pure: returns values.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "cosmic/admission.hpp"
#include "cosmic/config_loader.hpp"

namespace cosmic {

nlohmann::json to_json(const ChannelReport& channel);
nlohmann::json to_json(const SegmentLoad& segment);
nlohmann::json to_json(const AdmissionReport& report);
nlohmann::json to_json(const std::vector<ConfigError>& errors);

// `text` left-aligned in a column of `width` characters (at least one space after it).
std::string pad_column(const std::string& text, std::size_t width);

// A 29-bit CAN identifier with its fields in the segment's layout (docs/can-wire-format.md),
// e.g. "0x0402412C (FAMOUSO layout: priority 0x10, fragment 0, TxNode 9, etag 300)".
std::string can_identifier_text(std::uint32_t can_id, CanProfile profile);
// The identifier of a hop's plan: in the segment's layout, or a native channel's own
// ("0x123 (native, standard)").
std::string can_identifier_text(const CanHopPlan& plan);

std::string render_text(const AdmissionReport& report);
// One channel with every hop and every check.
std::string render_channel_text(const ChannelReport& channel);

}  // namespace cosmic
