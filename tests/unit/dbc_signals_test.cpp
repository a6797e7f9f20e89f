// The DBC reader's signals (cosmic/dbc.hpp): SG_ layouts, scaling, ranges, units and multiplexing,
// VAL_ names and SIG_VALTYPE_ floats applied wherever they stand in the file, and every problem with
// a signal located at its line and column.
#include "cosmic/build_paths.hpp"
#include "cosmic/dbc.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cosmic {
namespace {

std::vector<std::string> signal_errors(std::string_view text) {
  std::vector<std::string> out;
  for (const DbcError& e : parse_dbc(text).errors)
    out.push_back(std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  return out;
}

const DbcSignal& signal_named(const DbcMessage& m, std::string_view name) {
  for (const DbcSignal& s : m.signals) {
    if (s.name == name) return s;
  }
  throw std::runtime_error("no signal " + std::string(name));
}

TEST(DbcSignals, LayoutScalingRangeAndUnitOfEverySignal) {
  const DbcFile file = parse_dbc(R"dbc(BO_ 256 BodyStatus: 8 BCM
 SG_ Ignition : 0|2@1+ (1,0) [0|3] "" Dash,Gateway
 SG_ BatteryVoltage : 8|16@1+ (0.01,0) [0|655.35] "V" Dash,Gateway
 SG_ AmbientTemp : 24|8@1- (0.5,-40) [-40|87.5] "degC" Dash
 SG_ Torque : 39|12@0- (1E-1,+2.5) [-204.8|207.2] "N m"  Gateway
)dbc");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  ASSERT_EQ(file.messages.size(), 1u);
  const DbcMessage& m = file.messages[0];
  ASSERT_EQ(m.signals.size(), 4u);
  const DbcSignal& volts = signal_named(m, "BatteryVoltage");
  EXPECT_EQ(volts.start_bit, 8u);
  EXPECT_EQ(volts.size, 16u);
  EXPECT_EQ(volts.order, DbcByteOrder::little_endian);
  EXPECT_FALSE(volts.is_signed);
  EXPECT_DOUBLE_EQ(volts.factor, 0.01);
  EXPECT_DOUBLE_EQ(volts.maximum, 655.35);
  EXPECT_EQ(volts.unit, "V");
  EXPECT_EQ(volts.line, 3);
  EXPECT_EQ(volts.column, 2);
  const DbcSignal& temp = signal_named(m, "AmbientTemp");
  EXPECT_TRUE(temp.is_signed);
  EXPECT_DOUBLE_EQ(temp.offset, -40.0);
  EXPECT_DOUBLE_EQ(temp.minimum, -40.0);
  const DbcSignal& torque = signal_named(m, "Torque");
  EXPECT_EQ(torque.order, DbcByteOrder::big_endian);
  EXPECT_EQ(torque.start_bit, 39u);
  EXPECT_DOUBLE_EQ(torque.factor, 0.1);
  EXPECT_DOUBLE_EQ(torque.offset, 2.5);
  EXPECT_EQ(torque.unit, "N m");
  EXPECT_EQ(torque.value_type, DbcValueType::integer);
}

TEST(DbcSignals, ValueNamesAndFloatTypesApplyWhereverTheyStand) {
  const DbcFile file = parse_dbc(R"dbc(VAL_ 288 State 2 "Ajar" 0 "Closed" 1 "Open" ;
SIG_VALTYPE_ 300 Pressure : 1;
SIG_VALTYPE_ 300 Energy 2;
VAL_ Env 1 "an environment variable's names are skipped" ;
BO_ 288 DoorEvent: 2 DoorFL
 SG_ State : 8|2@1+ (1,0) [0|2] "" BCM
BO_ 300 Fluid: 16 Pump
 SG_ Pressure : 0|32@1- (1,0) [0|0] "bar" X
 SG_ Energy : 32|64@1- (1,0) [0|0] "J" X
)dbc");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  const DbcSignal& state = file.messages[0].signals[0];
  ASSERT_EQ(state.value_names.size(), 3u);
  EXPECT_EQ(state.value_names[0], (DbcValueName{0, "Closed"}));
  EXPECT_EQ(state.value_names[2], (DbcValueName{2, "Ajar"}));
  EXPECT_EQ(signal_named(file.messages[1], "Pressure").value_type, DbcValueType::float32);
  EXPECT_EQ(signal_named(file.messages[1], "Energy").value_type, DbcValueType::float64);
}

TEST(DbcSignals, MultiplexorAndMultiplexedSignals) {
  const DbcFile file = parse_dbc(R"dbc(BO_ 2566844672 Diag: 8 Tool
 SG_ Mode M : 0|8@1+ (1,0) [0|255] "" Ecu
 SG_ Dtc m0 : 8|16@1+ (1,0) [0|0] "" Ecu
 SG_ Freeze m1 : 8|32@1- (1,0) [0|0] "" Ecu
 SG_ Sub m2M : 8|8@1+ (1,0) [0|0] "" Ecu
)dbc");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  const DbcMessage& m = file.messages[0];
  EXPECT_EQ(signal_named(m, "Mode").multiplex, DbcMultiplex::multiplexor);
  EXPECT_EQ(signal_named(m, "Dtc").multiplex, DbcMultiplex::multiplexed);
  EXPECT_EQ(signal_named(m, "Freeze").multiplex_value, 1u);
  EXPECT_EQ(signal_named(m, "Sub").multiplex, DbcMultiplex::multiplexed_multiplexor);
  EXPECT_EQ(signal_named(m, "Sub").multiplex_value, 2u);
}

TEST(DbcSignals, TheBundledDbcFilesReadWithEverySignal) {
  for (const char* name : {"body.dbc", "powertrain_fd.dbc"}) {
    std::ifstream in(std::string(build_paths::dbc_dir) + "/" + name, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const DbcFile file = parse_dbc(text.str());
    EXPECT_TRUE(file.ok()) << name << ": " << (file.ok() ? "" : file.errors.front().message);
    std::size_t signals = 0;
    for (const DbcMessage& m : file.messages) signals += m.signals.size();
    EXPECT_GT(signals, 0u) << name;
  }
}

TEST(DbcSignals, EveryBadSignalIsLocated) {
  EXPECT_EQ(signal_errors("BO_ 1 A: 2 X\n SG_ S : 9|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:2: signal 'S' (9|8@1+) does not fit the 2 bytes of message 'A'"});
  // Motorola: bit 3 of byte 1 down through byte 2 needs 3 bytes.
  EXPECT_EQ(signal_errors("BO_ 1 A: 2 X\n SG_ S : 11|12@0+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:2: signal 'S' (11|12@0+) does not fit the 2 bytes of message 'A'"});
  EXPECT_EQ(signal_errors("BO_ 1 A: 8 X\n SG_ S : 0|65@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:12: signal size '65' is out of range (1..64 bits)"});
  EXPECT_EQ(signal_errors("BO_ 1 A: 8 X\n SG_ S : 0|8@2+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{
                "2:14: expected the byte order after '@': 1 (Intel, little endian) or 0 (Motorola, big endian), found "
                "'2'"});
  EXPECT_EQ(
      signal_errors("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (0,1) [0|0] \"\" X\n"),
      std::vector<std::string>{"2:18: factor 0 maps every raw value to the offset: a signal's factor must not be 0"});
  EXPECT_EQ(signal_errors("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [5|1] \"\" X\n"),
            std::vector<std::string>{"2:24: the minimum '5' is above the maximum"});
  EXPECT_EQ(signal_errors("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|1] X\n"),
            std::vector<std::string>{"2:29: expected the unit as a quoted string after the range, found 'X'"});
  EXPECT_EQ(signal_errors("BO_ 1 A: 8 X\n SG_ S m1 : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:2: signal 'S' is multiplexed, but message 'A' has no multiplexor switch (M)"});
  EXPECT_EQ(signal_errors("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n SG_ S : 8|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"3:2: duplicate signal name 'S' in message 'A'"});
}

TEST(DbcSignals, EveryBadReferenceIsLocated) {
  const std::string message = "BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n";
  EXPECT_EQ(signal_errors(message + "VAL_ 2 S 1 \"x\" ;\n"),
            std::vector<std::string>{"3:6: VAL_ names message id 2 (0x2), which no BO_ declares"});
  EXPECT_EQ(signal_errors(message + "VAL_ 1 T 1 \"x\" ;\n"),
            std::vector<std::string>{"3:6: VAL_ names signal 'T', which message 'A' does not declare"});
  EXPECT_EQ(signal_errors(message + "VAL_ 1 S 1 \"x\" 1 \"y\" ;\n"),
            std::vector<std::string>{"3:6: VAL_ names raw value 1 of signal 'S' twice"});
  EXPECT_EQ(signal_errors(message + "VAL_ 1 S 1.5 \"x\" ;\n"),
            std::vector<std::string>{"3:10: VAL_ value '1.5' is not a whole raw value"});
  EXPECT_EQ(signal_errors(message + "SIG_VALTYPE_ 1 S : 1;\n"),
            std::vector<std::string>{"3:14: SIG_VALTYPE_ makes signal 'S' an IEEE float of 32 bits, but it has 8"});
  EXPECT_EQ(signal_errors(message + "SIG_VALTYPE_ 1 S : 3;\n"),
            std::vector<std::string>{
                "3:20: expected the value type: 0 (integer), 1 (IEEE float, 32 bits) or 2 (IEEE double, 64 bits), "
                "found '3'"});
}

TEST(DbcSignals, SignalsOfAMessageThatIsNotKeptAreDropped) {
  const DbcFile file = parse_dbc("BO_ 4096 Bad: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\nBO_ 1 A: 1 X\n");
  ASSERT_EQ(file.errors.size(), 1u);  // the id's
  ASSERT_EQ(file.messages.size(), 1u);
  EXPECT_TRUE(file.messages[0].signals.empty());
}

TEST(DbcSignals, SignalsPerMessageAreBoundedAndReportedOnce) {
  std::string text = "BO_ 1 A: 64 X\n";
  for (std::size_t i = 0; i <= kDbcMaxSignalsPerMessage + 5; ++i) {
    text += " SG_ S" + std::to_string(i) + " : 0|1@1+ (1,0) [0|0] \"\" X\n";
  }
  const DbcFile file = parse_dbc(text);
  ASSERT_EQ(file.errors.size(), 1u);
  EXPECT_NE(file.errors[0].message.find("signals in message 'A'"), std::string::npos);
}

}  // namespace
}  // namespace cosmic
