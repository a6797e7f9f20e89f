// The parts of a CAN DBC file the gateway needs: every BO_ message's identifier, length and
// cycle time (GenMsgCycleTime), and its SG_ signals with their layout, scaling, range, unit,
// multiplexing, value table (VAL_) and IEEE float type (SIG_VALTYPE_), which a typed channel's
// fields come from (cosmic/dbc_type.hpp) and the DBC codec packs (cosmic/dbc_codec.hpp). Every
// other statement is walked and skipped. Pure: parses text, no file I/O; never throws. One pass,
// linear in the text's size up to sorting, bounded by the limits below so that a hostile file
// costs little.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/units.hpp"

namespace cosmic {

// A signal's byte order as SG_ writes it: @1 Intel (little endian; the start bit is the least
// significant bit), @0 Motorola (big endian; the start bit is the most significant bit, bits
// numbered 0..7 from the least significant bit of byte 0, 8..15 in byte 1, ...).
enum class DbcByteOrder : std::uint8_t { little_endian, big_endian };

// The raw value's type: an integer (SG_'s + or -), or an IEEE float (SIG_VALTYPE_ 1 for 32 bits,
// 2 for 64).
enum class DbcValueType : std::uint8_t { integer, float32, float64 };

// Simple multiplexing: the multiplexor switch (M) selects which multiplexed signals (m<n>) the frame
// carries; m<n>M (a multiplexed switch, extended multiplexing) is read but not decoded.
enum class DbcMultiplex : std::uint8_t { none, multiplexor, multiplexed, multiplexed_multiplexor };

struct DbcValueName {
  std::int64_t value = 0;  // a raw value, as VAL_ writes it
  std::string name;
  friend bool operator==(const DbcValueName&, const DbcValueName&) = default;
};

struct DbcSignal {
  std::string name;
  std::uint32_t start_bit = 0;  // as SG_ writes it (see DbcByteOrder)
  std::uint32_t size = 1;       // bits, 1..64 (32 or 64 for IEEE floats)
  DbcByteOrder order = DbcByteOrder::little_endian;
  bool is_signed = false;
  DbcValueType value_type = DbcValueType::integer;
  double factor = 1.0, offset = 0.0;    // physical = raw * factor + offset
  double minimum = 0.0, maximum = 0.0;  // the physical range; both 0 means none declared
  std::string unit;
  DbcMultiplex multiplex = DbcMultiplex::none;
  std::uint32_t multiplex_value = 0;      // multiplexed: the switch value that selects this signal
  std::vector<DbcValueName> value_names;  // VAL_, ordered by value
  int line = 0, column = 0;               // 1-based, of the SG_ keyword
  friend bool operator==(const DbcSignal&, const DbcSignal&) = default;
};

struct DbcMessage {
  std::string name;          // BO_ name
  std::uint32_t can_id = 0;  // identifier without the extended flag (11 or 29 bits)
  bool extended = false;     // bit 31 of the DBC id was set
  std::uint32_t length = 0;  // data bytes as the DBC declares (0..64; > 8 means CAN FD)
  std::optional<Nanos>
      cycle_time;  // GenMsgCycleTime (explicit BA_, else the BA_DEF_DEF_ default); nullopt when none or 0
  std::vector<DbcSignal> signals;  // file order
  int line = 0, column = 0;        // 1-based, of the BO_ keyword
  friend bool operator==(const DbcMessage&, const DbcMessage&) = default;
};

// line and column are 1-based; both are 0 for a problem of the whole text (its size) and for the
// closing line that counts the errors left unreported.
// How many problems a reader of a text file (DBC, LCM, IDL, .msg) reports at most; one closing line
// then counts the rest.
inline constexpr std::size_t kMaxReportedTextErrors = 100;

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
// SG_ lines beyond this many in one message, or in the whole file, are an error and not returned.
inline constexpr std::size_t kDbcMaxSignalsPerMessage = 1'024;
inline constexpr std::size_t kDbcMaxSignals = 200'000;
// VAL_ names of one signal beyond this many are an error.
inline constexpr std::size_t kDbcMaxValueNames = 1'024;
// Errors beyond this many are counted in one closing line instead of reported.
inline constexpr std::size_t kDbcMaxReportedErrors = 100;

DbcFile parse_dbc(std::string_view text);

}  // namespace cosmic
