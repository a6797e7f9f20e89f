// A typed channel's contents from a DBC message (cosmic/dbc_type.hpp): each signal's physical type,
// unit and range, value tables as enumerations with identifier names, multiplexed signals present
// only when selected, and located refusals of what a type cannot hold.
#include "cosmic/dbc_type.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace cosmic {
namespace {

ChannelType type_of(std::string_view dbc) {
  const DbcFile file = parse_dbc(dbc);
  EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.errors.front().message);
  if (file.messages.empty()) return {};
  const DbcChannelType typed = channel_type_from_dbc(file.messages.front());
  EXPECT_TRUE(typed.ok()) << (typed.ok() ? "" : typed.errors.front().message);
  return typed.type;
}

std::vector<std::string> type_errors(std::string_view dbc) {
  const DbcFile file = parse_dbc(dbc);
  EXPECT_TRUE(file.ok());
  std::vector<std::string> out;
  if (file.messages.empty()) return out;
  for (const DbcError& e : channel_type_from_dbc(file.messages.front()).errors)
    out.push_back(std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  return out;
}

TEST(DbcType, EachSignalGetsItsPhysicalType) {
  const ChannelType type = type_of(R"dbc(BO_ 256 BodyStatus: 8 BCM
 SG_ Ignition : 0|2@1+ (1,0) [0|3] "" Dash
 SG_ BatteryVoltage : 8|16@1+ (0.01,0) [0|655.35] "V" Dash
 SG_ AmbientTemp : 24|8@1- (0.5,-40) [-40|87.5] "degC" Dash
 SG_ Gear : 32|4@1- (1,0) [0|0] "" Dash
 SG_ Odometer : 36|20@1+ (10,-100) [0|0] "m" Dash
 SG_ Brake : 56|1@1+ (1,0) [0|0] "" Dash
 SG_ Wide : 57|7@1+ (1,0) [0|1000] "" Dash
)dbc");
  EXPECT_EQ(describe(type),
            "{Ignition: uint8 [0..3], BatteryVoltage: float64 [V, 0..655.35], AmbientTemp: float64 [degC, -40..87.5], "
            "Gear: int8, Odometer: int32 [m], Brake: bool, Wide: uint16 [0..1000]}");
}

TEST(DbcType, FloatSignalsStayFloats) {
  const ChannelType type = type_of(R"dbc(BO_ 300 Fluid: 16 Pump
 SG_ Pressure : 0|32@1- (1,0) [0|0] "bar" X
 SG_ Scaled : 32|32@1- (2,0) [0|0] "" X
 SG_ Energy : 64|64@1- (1,0) [0|0] "J" X
SIG_VALTYPE_ 300 Pressure : 1;
SIG_VALTYPE_ 300 Scaled : 1;
SIG_VALTYPE_ 300 Energy : 2;
)dbc");
  EXPECT_EQ(describe(type), "{Pressure: float32 [bar], Scaled: float64, Energy: float64 [J]}");
}

TEST(DbcType, ValueTablesBecomeEnumerationsOfRawValues) {
  const ChannelType type = type_of(R"dbc(BO_ 288 DoorEvent: 2 DoorFL
 SG_ State : 8|2@1+ (1,0) [0|2] "" BCM
 SG_ Lamp : 0|8@1- (1,0) [0|0] "" BCM
VAL_ 288 State 2 "Ajar" 1 "Open (latched)" 0 "Closed" ;
VAL_ 288 Lamp -1 "Not available" 3 "3rd" 4 "3rd" 5 "" ;
)dbc");
  ASSERT_EQ(type.fields.size(), 2u);
  EXPECT_EQ(describe(type.fields[0].type), "enum uint8 {Closed=0, Open_latched=1, Ajar=2}");
  EXPECT_EQ(describe(type.fields[1].type), "enum int8 {Not_available=-1, v3rd=3, v3rd_4=4, v5=5}");
  EXPECT_TRUE(type.fields[0].unit.empty());
  EXPECT_FALSE(type.fields[0].minimum);  // a range belongs to numbers, not to names
}

TEST(DbcType, MultiplexedSignalsArePresentWhenTheSwitchSelectsThem) {
  const ChannelType type = type_of(R"dbc(BO_ 2566844672 Diag: 8 Tool
 SG_ Mode M : 0|8@1+ (1,0) [0|255] "" Ecu
 SG_ Dtc m0 : 8|16@1+ (1,0) [0|0] "" Ecu
 SG_ Freeze m1 : 8|32@1- (1,0) [0|0] "" Ecu
)dbc");
  EXPECT_EQ(describe(type), "{Mode: uint8 [0..255], Dtc: uint16 when Mode=0, Freeze: int32 when Mode=1}");
  EXPECT_TRUE(check_type(type).empty());
}

TEST(DbcType, WhatATypeCannotHoldIsRefusedAtTheSignal) {
  EXPECT_EQ(type_errors("BO_ 1 A: 8 X\n SG_ _s : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{
                "2:2: signal name '_s' is not a field name ([A-Za-z][A-Za-z0-9_]*, at most 64 characters)"});
  EXPECT_EQ(
      type_errors("BO_ 1 A: 8 X\n SG_ M0 M : 0|8@1+ (1,0) [0|0] \"\" X\n SG_ Sub m1M : 8|8@1+ (1,0) [0|0] \"\" X\n"),
      std::vector<std::string>{"3:2: signal 'Sub' is itself a multiplexor inside a multiplexed frame "
                               "(extended multiplexing), which typed channels do not decode"});
  EXPECT_EQ(
      type_errors("BO_ 1 A: 8 X\n SG_ P : 0|12@1+ (1,0) [0|0] \"\" X\n SG_ Q : 15|8@0+ (1,0) [0|0] \"\" X\n"),
      std::vector<std::string>{"3:2: signal 'Q' shares bits of byte 1 with signal 'P', which the same frame carries"});
  // Multiplexed by different switch values, they never meet in one frame.
  EXPECT_TRUE(type_errors("BO_ 1 A: 8 X\n SG_ M M : 0|8@1+ (1,0) [0|0] \"\" X\n SG_ P m0 : 8|16@1+ (1,0) [0|0] \"\" X\n"
                          " SG_ Q m1 : 8|8@1+ (1,0) [0|0] \"\" X\n")
                  .empty());
  EXPECT_EQ(type_errors("BO_ 1 A: 8 X\n"),
            std::vector<std::string>{"1:1: message 'A' has no signals to make fields of"});
}

TEST(DbcType, TheSwitchComesFirstWhereverTheFileDeclaresIt) {
  const ChannelType type = type_of(R"dbc(BO_ 1 Diag: 8 X
 SG_ Dtc m0 : 8|16@1+ (1,0) [0|0] "" X
 SG_ Mode M : 0|8@1+ (1,0) [0|0] "" X
 SG_ Level m1 : 8|8@1+ (1,0) [0|0] "" X
)dbc");
  EXPECT_EQ(describe(type), "{Mode: uint8, Dtc: uint16 when Mode=0, Level: uint8 when Mode=1}");
  // A one-bit switch is an integer field (a selector), not a bool.
  EXPECT_EQ(
      describe(type_of("BO_ 1 A: 8 X\n SG_ P m1 : 8|8@1+ (1,0) [0|0] \"\" X\n SG_ M M : 0|1@1+ (1,0) [0|0] \"\" X\n")),
      "{M: uint8, P: uint8 when M=1}");
  // A whole scaling applies to the switch's value too.
  EXPECT_EQ(
      describe(type_of("BO_ 1 A: 8 X\n SG_ M M : 0|4@1+ (2,10) [0|0] \"\" X\n SG_ P m3 : 8|8@1+ (1,0) [0|0] \"\" X\n")),
      "{M: uint8, P: uint8 when M=16}");
}

TEST(DbcType, SwitchesThatCannotSelectAreRefused) {
  EXPECT_EQ(type_errors("BO_ 1 A: 8 X\n SG_ M M : 0|4@1- (1,0) [0|0] \"\" X\n SG_ P m1 : 8|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:2: multiplexor switch 'M' is signed: the switch's values are the unsigned raw "
                                     "values its multiplexed signals name"});
  EXPECT_EQ(
      type_errors("BO_ 1 A: 8 X\n SG_ M M : 0|4@1+ (0.5,0) [0|0] \"\" X\n SG_ P m1 : 8|8@1+ (1,0) [0|0] \"\" X\n"),
      std::vector<std::string>{"2:2: multiplexor switch 'M' is not an integer field (an IEEE float, or a scaling "
                               "that is not whole): the switch's values are the unsigned raw values its "
                               "multiplexed signals name"});
  EXPECT_EQ(type_errors("BO_ 1 A: 8 X\n SG_ M M : 0|2@1+ (1,0) [0|0] \"\" X\n SG_ P m4 : 8|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"3:2: signal 'P' is selected by 'M' = 4, which the switch's 2 bits cannot hold"});
}

TEST(DbcType, SixtyFourBitValuesPickATypeThatHoldsThemExactly) {
  // Physical 1..2^64 fits no 64-bit integer: float64, never a wrapped uint64.
  EXPECT_EQ(describe(type_of("BO_ 1 A: 8 X\n SG_ S : 0|64@1+ (1,1) [0|0] \"\" X\n")), "{S: float64}");
  EXPECT_EQ(describe(type_of("BO_ 1 A: 8 X\n SG_ S : 0|64@1+ (1,0) [0|0] \"\" X\n")), "{S: uint64}");
  EXPECT_EQ(describe(type_of("BO_ 1 A: 8 X\n SG_ S : 0|64@1- (1,0) [0|0] \"\" X\n")), "{S: int64}");
  EXPECT_EQ(describe(type_of("BO_ 1 A: 8 X\n SG_ S : 0|64@1- (-1,0) [0|0] \"\" X\n")), "{S: float64}");
  EXPECT_EQ(describe(type_of("BO_ 1 A: 8 X\n SG_ S : 0|63@1+ (1,0) [0|0] \"\" X\n")), "{S: uint64}");
  EXPECT_EQ(type_errors("BO_ 1 A: 8 X\n SG_ S : 0|64@1+ (1,0) [0|0] \"\" X\nVAL_ 1 S -1 \"none\" ;\n"),
            std::vector<std::string>{"2:2: signal 'S': no integer holds both its raw values and the negative values "
                                     "its value table names"});
}

TEST(DbcType, EnumerationNamesStayUniqueAndShort) {
  const ChannelType type =
      type_of("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\nVAL_ 1 S 1 \"A\" 2 \"A 3\" 3 \"A\" 4 \"" +
              std::string(70, 'b') + "\" 5 \"" + std::string(70, 'b') + "\" ;\n");
  ASSERT_EQ(type.fields.size(), 1u);
  EXPECT_EQ(describe(type.fields[0].type),
            "enum uint8 {A=1, A_3=2, A_3_1=3, " + std::string(64, 'b') + "=4, " + std::string(62, 'b') + "_5=5}");
  EXPECT_TRUE(check_type(type).empty());
}

TEST(DbcType, ValueIdentifiers) {
  EXPECT_EQ(dbc_value_identifier("Not available", 7), "Not_available");
  EXPECT_EQ(dbc_value_identifier("  --Off--  ", 0), "Off");
  EXPECT_EQ(dbc_value_identifier("0x1F", 31), "v0x1F");
  EXPECT_EQ(dbc_value_identifier("-", -3), "v3");
  EXPECT_EQ(dbc_value_identifier("Zündung ein", 1), "Z_ndung_ein");
  EXPECT_EQ(dbc_value_identifier(std::string(100, 'a'), 1).size(), 64u);
  EXPECT_EQ(dbc_value_identifier("-", std::numeric_limits<std::int64_t>::min()), "v9223372036854775808");
}

}  // namespace
}  // namespace cosmic
