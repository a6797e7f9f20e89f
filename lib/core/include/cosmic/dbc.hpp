// The parts of a CAN DBC file the gateway needs: every BO_ message's identifier, length and
// cycle time (GenMsgCycleTime). Every other statement is walked and skipped. Pure: parses text,
// no file I/O; never throws. One pass, linear in the text's size, bounded by the limits below so
// that a hostile file costs little.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/units.hpp"

namespace cosmic {

struct DbcMessage {
  std::string name;          // BO_ name
  std::uint32_t can_id = 0;  // identifier without the extended flag (11 or 29 bits)
  bool extended = false;     // bit 31 of the DBC id was set
  std::uint32_t length = 0;  // data bytes as the DBC declares (0..64; > 8 means CAN FD)
  std::optional<Nanos>
      cycle_time;            // GenMsgCycleTime (explicit BA_, else the BA_DEF_DEF_ default); nullopt when none or 0
  int line = 0, column = 0;  // 1-based, of the BO_ keyword
};

// line and column are 1-based; both are 0 for a problem of the whole text (its size) and for the
// closing line that counts the errors left unreported.
struct DbcError {
  int line = 0;
  int column = 0;
  std::string message;
};

struct DbcFile {
  std::vector<DbcMessage> messages;  // file order
  std::vector<DbcError> errors;      // every problem found (capped, with one closing line counting the rest)
  bool ok() const { return errors.empty(); }
};

// A longer text is refused as a whole, unread.
inline constexpr std::size_t kDbcMaxTextBytes = std::size_t{8} * 1024 * 1024;
// BO_ lines beyond this many are an error and not returned.
inline constexpr std::size_t kDbcMaxMessages = 20'000;
// Errors beyond this many are counted in one closing line instead of reported.
inline constexpr std::size_t kDbcMaxReportedErrors = 100;

DbcFile parse_dbc(std::string_view text);

}  // namespace cosmic
