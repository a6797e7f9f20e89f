// OMG IDL type files (cosmic/idl_types.hpp): ROS 2's rosidl output (Twist over Vector3, LaserScan
// over Header over Time through #include, constants modules, array typedefs, units) and idlc
// users' IDL (enums with @value, nested modules, bounded strings and sequences, multi-dimensional
// arrays, extensibility), the types typed channels get from them, every refusal at its location,
// and a sample serialized by hand that decodes through CdrRepresentation built from the parsed type
// (the mapping is CDR's). tests/integration/idl_types checks the same against Cyclone's idlc.
#include "cosmic/idl_types.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <map>
#include <string>
#include <vector>

#include "cosmic/cdr_representation.hpp"

namespace cosmic {
// Its own namespace: unity builds merge test files, whose anonymous helpers must not clash.
namespace idl_test {
namespace {

// As rosidl_adapter writes them (msg.idl.em) from the public .msg definitions; comments shortened.
const std::map<std::string, std::string> kRos2Files = {
    {"geometry_msgs/msg/Vector3.idl", R"idl(// generated from rosidl_adapter/resource/msg.idl.em
// with input from geometry_msgs/msg/Vector3.msg
// generated code does not contain a copyright notice


module geometry_msgs {
  module msg {
    @verbatim (language="comment", text=
      "This represents a vector in free space." "\n"
      "It is only meant to represent a direction.")
    struct Vector3 {
      double x;

      double y;

      double z;
    };
  };
};
)idl"},
    {"geometry_msgs/msg/Twist.idl", R"idl(// generated from rosidl_adapter/resource/msg.idl.em
// with input from geometry_msgs/msg/Twist.msg
// generated code does not contain a copyright notice

#include "geometry_msgs/msg/Vector3.idl"

module geometry_msgs {
  module msg {
    @verbatim (language="comment", text=
      "This expresses velocity in free space broken into its linear and angular parts.")
    struct Twist {
      geometry_msgs::msg::Vector3 linear;

      geometry_msgs::msg::Vector3 angular;
    };
  };
};
)idl"},
    {"builtin_interfaces/msg/Time.idl", R"idl(// generated from rosidl_adapter/resource/msg.idl.em
// with input from builtin_interfaces/msg/Time.msg
// generated code does not contain a copyright notice


module builtin_interfaces {
  module msg {
    @verbatim (language="comment", text=
      "This message communicates ROS Time defined here:" "\n"
      "https://design.ros2.org/articles/clock_and_time.html")
    struct Time {
      @verbatim (language="comment", text=
        "The seconds component, valid over all int32 values.")
      int32 sec;

      @verbatim (language="comment", text=
        "The nanoseconds component, valid in the range [0, 10e9).")
      uint32 nanosec;
    };
  };
};
)idl"},
    {"std_msgs/msg/Header.idl", R"idl(// generated from rosidl_adapter/resource/msg.idl.em
// with input from std_msgs/msg/Header.msg
// generated code does not contain a copyright notice

#include "builtin_interfaces/msg/Time.idl"

module std_msgs {
  module msg {
    @verbatim (language="comment", text=
      "Standard metadata for higher-level stamped data types.")
    struct Header {
      @verbatim (language="comment", text=
        "Two-integer timestamp that is expressed as seconds and nanoseconds.")
      builtin_interfaces::msg::Time stamp;

      @verbatim (language="comment", text=
        "Transform frame with which this data is associated.")
      string frame_id;
    };
  };
};
)idl"},
    {"sensor_msgs/msg/LaserScan.idl", R"idl(// generated from rosidl_adapter/resource/msg.idl.em
// with input from sensor_msgs/msg/LaserScan.msg
// generated code does not contain a copyright notice

#include "std_msgs/msg/Header.idl"

module sensor_msgs {
  module msg {
    @verbatim (language="comment", text=
      "Single scan from a planar laser range-finder")
    struct LaserScan {
      @verbatim (language="comment", text=
        "timestamp in the header is the acquisition time of the first ray in the scan.")
      std_msgs::msg::Header header;

      @verbatim (language="comment", text=
        "start angle of the scan")
      @unit (value="rad")
      float angle_min;

      @unit (value="rad")
      float angle_max;

      @unit (value="rad")
      float angle_increment;

      @unit (value="s")
      float time_increment;

      @unit (value="s")
      float scan_time;

      @unit (value="m")
      float range_min;

      @unit (value="m")
      float range_max;

      @unit (value="m")
      sequence<float> ranges;

      sequence<float> intensities;
    };
  };
};
)idl"},
    {"sensor_msgs/msg/BatteryState.idl", R"idl(// generated from rosidl_adapter/resource/msg.idl.em
// with input from sensor_msgs/msg/BatteryState.msg (a part of it)

#include "std_msgs/msg/Header.idl"

module sensor_msgs {
  module msg {
    typedef float float__3[3];
    module BatteryState_Constants {
      @verbatim (language="comment", text=
        "Power supply status constants")
      const uint8 POWER_SUPPLY_STATUS_UNKNOWN = 0;
      const uint8 POWER_SUPPLY_STATUS_CHARGING = 1;
      const uint8 POWER_SUPPLY_STATUS_FULL = 4;
    };
    struct BatteryState {
      std_msgs::msg::Header header;

      @unit (value="V")
      float voltage;

      @default (value=0.0)
      float percentage;

      uint8 power_supply_status;

      boolean present;

      float__3 cell_temperature;

      string<16> location;
    };
  };
};
)idl"},
};

IdlIncludeLoader ros2_loader() {
  return [](std::string_view name) -> std::optional<std::string> {
    const auto hit = kRos2Files.find(std::string(name));
    if (hit == kRos2Files.end()) return std::nullopt;
    return hit->second;
  };
}

IdlTypeFile ros2_file(const std::string& name) { return parse_idl_types(kRos2Files.at(name), ros2_loader()); }

std::vector<std::string> idl_errors(std::string_view text, const IdlIncludeLoader& load = nullptr) {
  std::vector<std::string> out;
  for (const IdlError& e : parse_idl_types(text, load).errors) {
    out.push_back((e.file.empty() ? "" : e.file + ":") + std::to_string(e.line) + ":" + std::to_string(e.column) +
                  ": " + e.message);
  }
  return out;
}

std::string idl_described(const IdlTypeFile& file, std::string_view name,
                          const std::map<std::string, std::uint32_t>& max_length = {}) {
  const IdlStruct* s = file.find(name);
  if (s == nullptr) return "no struct " + std::string(name);
  const IdlChannelType typed = idl_channel_type(file, *s, max_length);
  if (!typed.ok()) return "refused: " + typed.errors.front().message;
  return describe(typed.type);
}

constexpr std::string_view kVectorText = "{x: float64, y: float64, z: float64}";

TEST(IdlTypes, Ros2TwistOverVector3ThroughAnInclude) {
  const IdlTypeFile file = ros2_file("geometry_msgs/msg/Twist.idl");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  EXPECT_EQ(file.includes, std::vector<std::string>{"geometry_msgs/msg/Vector3.idl"});
  ASSERT_EQ(file.structs.size(), 2u);
  EXPECT_EQ(file.structs[0].file, "geometry_msgs/msg/Vector3.idl");
  const IdlStruct* twist = file.find("geometry_msgs::msg::Twist");
  ASSERT_NE(twist, nullptr);
  EXPECT_EQ(file.find("::geometry_msgs::msg::Twist"), twist);
  EXPECT_EQ(twist->comment, "This expresses velocity in free space broken into its linear and angular parts.");
  EXPECT_EQ(file.find("geometry_msgs::msg::Vector3")->comment,
            "This represents a vector in free space.\nIt is only meant to represent a direction.");
  EXPECT_EQ(twist->members[0].type.kind, IdlType::Kind::structure);
  EXPECT_EQ(twist->members[0].type.name, "geometry_msgs::msg::Vector3");
  EXPECT_FALSE(twist->extensibility_declared);
  const IdlChannelType typed = idl_channel_type(file, *twist);
  ASSERT_TRUE(typed.ok()) << typed.errors.front().message;
  EXPECT_EQ(typed.extensibility, CdrExtensibility::final_type);  // unannotated: final, as ROS 2 writes it
  EXPECT_EQ(describe(typed.type),
            "{linear: " + std::string(kVectorText) + ", angular: " + std::string(kVectorText) + "}");
  // 52 bytes on DDS: the 4-byte header and six doubles.
  EXPECT_EQ(CdrRepresentation::make(typed.type, DdsRepresentation::xcdr1, typed.extensibility).value().max_wire_size(),
            52u);
}

TEST(IdlTypes, Ros2LaserScanWithItsHeaderAndUnboundedSequences) {
  const IdlTypeFile file = ros2_file("sensor_msgs/msg/LaserScan.idl");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  EXPECT_EQ(file.includes, (std::vector<std::string>{"std_msgs/msg/Header.idl", "builtin_interfaces/msg/Time.idl"}));
  const IdlStruct* scan = file.find("sensor_msgs::msg::LaserScan");
  ASSERT_NE(scan, nullptr);
  EXPECT_EQ(scan->members[1].unit, "rad");
  EXPECT_EQ(scan->members[1].comment, "start angle of the scan");
  // Two unbounded sequences of floats at kMaxTypeBound each are more scalars than a type holds.
  const IdlChannelType unbounded = idl_channel_type(file, *scan);
  ASSERT_EQ(unbounded.errors.size(), 1u);
  EXPECT_NE(unbounded.errors[0].message.find("(max_length: {MEMBER: N} bounds an unbounded sequence or string)"),
            std::string::npos)
      << unbounded.errors[0].message;
  EXPECT_EQ(idl_described(file, "sensor_msgs::msg::LaserScan",
                          {{"ranges", 1081}, {"intensities", 1081}, {"header.frame_id", 32}}),
            "{header: {stamp: {sec: int32, nanosec: uint32}, frame_id: string<=32>}, angle_min: float32 [rad], "
            "angle_max: float32 [rad], angle_increment: float32 [rad], time_increment: float32 [s], scan_time: "
            "float32 [s], range_min: float32 [m], range_max: float32 [m], ranges: sequence<float32, 1081> [m], "
            "intensities: sequence<float32, 1081>}");
  // Without max_length an unbounded string reads at kMaxTypeBound.
  EXPECT_EQ(idl_described(file, "std_msgs::msg::Header"),
            "{stamp: {sec: int32, nanosec: uint32}, frame_id: string<=65536>}");
}

TEST(IdlTypes, MaxLengthNamesStringsAndSequencesByPath) {
  const IdlTypeFile file = ros2_file("sensor_msgs/msg/LaserScan.idl");
  const IdlChannelType wrong = idl_channel_type(file, *file.find("sensor_msgs::msg::LaserScan"),
                                                {{"ranges", 0}, {"angle_min", 3}, {"header.nope", 2}});
  std::vector<std::string> messages;
  for (const IdlError& e : wrong.errors) messages.push_back(std::to_string(e.line) + ": " + e.message);
  EXPECT_EQ(messages, (std::vector<std::string>{
                          "40: member ranges of sensor_msgs::msg::LaserScan: max_length 0 of ranges is not 1..65536",
                          "11: max_length names angle_min, which is not a string or sequence of "
                          "sensor_msgs::msg::LaserScan",
                          "11: max_length names header.nope, which is not a string or sequence of "
                          "sensor_msgs::msg::LaserScan"}));
  // Elements by "[]"; a bounded string only tighter.
  const IdlTypeFile nested = parse_idl_types(
      "struct Name { string<8> first; };\n"
      "struct Names { sequence<string> words; sequence<Name, 4> people; string tags[2]; };\n");
  ASSERT_TRUE(nested.ok()) << nested.errors.front().message;
  EXPECT_EQ(idl_described(nested, "Names", {{"words", 3}, {"words[]", 10}, {"people[].first", 4}, {"tags[]", 5}}),
            "{words: sequence<string<=10>, 3>, people: sequence<{first: string<=4>}, 4>, tags: string<=5>[2]}");
  EXPECT_EQ(idl_described(nested, "Names", {{"words", 3}, {"words[]", 10}, {"people[].first", 9}, {"tags[]", 5}}),
            "refused: member first of Name: max_length 9 of people[].first is not 1..8");
  // A declared bound beyond what a channel's type holds needs max_length.
  const IdlTypeFile big = parse_idl_types("struct Big { string<70000> text; };");
  EXPECT_EQ(idl_described(big, "Big"),
            "refused: member text of Big: bound 70000 is beyond 65536, the most a channel's type holds (max_length: "
            "{text: N} bounds it tighter)");
  EXPECT_EQ(idl_described(big, "Big", {{"text", 100}}), "{text: string<=100>}");
}

TEST(IdlTypes, ConstantsModulesTypedefsAndDefaults) {
  const IdlTypeFile file = ros2_file("sensor_msgs/msg/BatteryState.idl");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  ASSERT_EQ(file.constants.size(), 3u);
  const IdlConstant* full = file.find_constant("sensor_msgs::msg::BatteryState_Constants::POWER_SUPPLY_STATUS_FULL");
  ASSERT_NE(full, nullptr);
  EXPECT_EQ(full->value, "4");
  EXPECT_EQ(full->type.scalar, ScalarKind::uint8);
  EXPECT_EQ(file.constants[0].comment, "Power supply status constants");
  const IdlStruct* battery = file.find("sensor_msgs::msg::BatteryState");
  EXPECT_EQ(battery->members[2].default_value, "0.0");
  EXPECT_EQ(file.find_typedef("sensor_msgs::msg::float__3")->dimensions, std::vector<std::uint32_t>{3});
  EXPECT_EQ(idl_described(file, "sensor_msgs::msg::BatteryState", {{"header.frame_id", 16}}),
            "{header: {stamp: {sec: int32, nanosec: uint32}, frame_id: string<=16>}, voltage: float32 [V], "
            "percentage: float32, power_supply_status: uint8, present: bool, cell_temperature: float32[3], "
            "location: string<=16>}");
  const IdlTypeFile literals = parse_idl_types(R"idl(module k {
  const short NEG = -32768;
  const unsigned long long BIG = 0xFFFFFFFFFFFFFFFF;
  const long OCT = 017;
  const double D = -1.5e3;
  const float F = 2;
  const boolean B = FALSE;
  const string<8> S = "a\tb" "\x41";
  const long N = 3;
  struct UsesN { string<N> s; long a[N]; };
};
)idl");
  ASSERT_TRUE(literals.ok()) << literals.errors.front().message;
  std::vector<std::string> values;
  for (const IdlConstant& c : literals.constants) values.push_back(c.value);
  EXPECT_EQ(values,
            (std::vector<std::string>{"-32768", "18446744073709551615", "15", "-1.5e3", "2", "FALSE", "a\tbA", "3"}));
  EXPECT_EQ(idl_described(literals, "k::UsesN"), "{s: string<=3>, a: int32[3]}");
}

TEST(IdlTypes, EnumsNestedModulesArraysAndEveryPrimitive) {
  const IdlTypeFile file = parse_idl_types(R"idl(
module outer {
  enum Color { RED, GREEN, BLUE };
  module inner {
    enum Mode { @value(3) IDLE, RUN, @value(10) FAULT };
    @final struct Cell {
      Color color;
      Mode mode;
      sequence<Mode, 2> history;
    };
  };
  typedef inner::Cell Row[3];
  struct Grid {
    Row rows[2];
    double m[2][3];
    short s; unsigned short us; long l; unsigned long ul; long long ll; unsigned long long ull;
    int8 i8; uint8 u8; int16 i16; uint16 u16; int32 i32; uint32 u32; int64 i64; uint64 u64;
    octet o; char c; boolean b; float f; double d;
    @range(min=-5, max=5.5) float ranged;
    @min(0) @max(100) @unit("%") octet percent;
  };
};
)idl");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  EXPECT_EQ(file.find_enum("outer::inner::Mode")->values,
            (std::vector<EnumValue>{{"IDLE", 3}, {"RUN", 4}, {"FAULT", 10}}));
  EXPECT_TRUE(file.find("outer::inner::Cell")->extensibility_declared);
  EXPECT_EQ(idl_described(file, "outer::Grid"),
            "{rows: {color: enum int32 {RED=0, GREEN=1, BLUE=2}, mode: enum int32 {IDLE=3, RUN=4, FAULT=10}, "
            "history: sequence<enum int32 {IDLE=3, RUN=4, FAULT=10}, 2>}[3][2], m: float64[3][2], s: int16, us: "
            "uint16, l: int32, ul: uint32, ll: int64, ull: uint64, i8: int8, u8: uint8, i16: int16, u16: uint16, "
            "i32: int32, u32: uint32, i64: int64, u64: uint64, o: uint8, c: int8, b: bool, f: float32, d: float64, "
            "ranged: float32 [-5..5.5], percent: uint8 [%, 0..100]}");
  // rows: an array of 2 of Row (an array of 3 cells); m[2][3]: an array of 2 arrays of 3.
  const IdlChannelType typed = idl_channel_type(file, *file.find("outer::Grid"));
  EXPECT_EQ(typed.type.fields[0].type.bound, 2u);
  EXPECT_EQ(typed.type.fields[0].type.element[0].bound, 3u);
  EXPECT_EQ(typed.type.fields[1].type.bound, 2u);
  EXPECT_EQ(typed.type.fields[1].type.element[0].bound, 3u);
}

TEST(IdlTypes, ExtensibilityIsRecordedAndOneForTheWholeType) {
  const IdlTypeFile file = parse_idl_types(R"idl(
@appendable struct A { long x; };
@extensibility(APPENDABLE) struct B { A a; };
struct C { A a; };
)idl");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  const IdlChannelType b = idl_channel_type(file, *file.find("B"));
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.extensibility, CdrExtensibility::appendable);
  const IdlChannelType c = idl_channel_type(file, *file.find("C"));
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_EQ(c.errors[0].line, 4);
  EXPECT_EQ(c.errors[0].message,
            "member a of C: struct A is @appendable but C is @final: a channel's CDR form gives every nested struct "
            "the extensibility of the whole");
}

TEST(IdlTypes, IncludesAreReadOnceThroughTheLoaderAndGuardsAreNoOps) {
  std::vector<std::string> asked;
  const std::map<std::string, std::string> files = {
      {"a.idl", "#ifndef A_IDL\n#define A_IDL\nstruct A { long x; };\n#endif  // A_IDL\n"},
      {"b.idl", "#include \"a.idl\"\nstruct B { A a; };\n"},
      {"self.idl", "#include <self.idl>\n"},
  };
  const IdlIncludeLoader load = [&](std::string_view name) -> std::optional<std::string> {
    asked.emplace_back(name);
    const auto hit = files.find(std::string(name));
    return hit == files.end() ? std::nullopt : std::optional<std::string>(hit->second);
  };
  const IdlTypeFile file = parse_idl_types("#include \"a.idl\"\n#include <b.idl>\nstruct C { B b; A a; };\n", load);
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  EXPECT_EQ(asked, (std::vector<std::string>{"a.idl", "b.idl"}));
  EXPECT_EQ(idl_described(file, "C"), "{b: {a: {x: int32}}, a: {x: int32}}");
  // Without a loader the names are recorded only.
  const IdlTypeFile unread = parse_idl_types("#include \"a.idl\"\nstruct D { long y; };\n");
  EXPECT_TRUE(unread.ok());
  EXPECT_EQ(unread.includes, std::vector<std::string>{"a.idl"});
  EXPECT_EQ(idl_errors("#include \"missing.idl\"\n#include \"self.idl\"\nstruct E { A a; };\n", load),
            (std::vector<std::string>{"self.idl:1:1: #include cycle: 'self.idl' includes itself",
                                      "1:1: cannot read the included file 'missing.idl'",
                                      "3:12: type 'A' is not declared before its use (nor in the files included)"}));
}

TEST(IdlTypes, EveryRefusalIsLocatedWithItsReason) {
  EXPECT_EQ(idl_errors("struct K {\n  @key long id;\n  long v;\n};"),
            std::vector<std::string>{
                "2:3: @key makes a keyed type, which is not read: the gateway does not compute key hashes"});
  EXPECT_EQ(idl_errors("struct K { @key(FALSE) long id; };"), std::vector<std::string>{});
  EXPECT_EQ(idl_errors("struct O { @optional long id; };"),
            std::vector<std::string>{"1:12: @optional members are not read: a channel's type has no absent fields"});
  EXPECT_EQ(idl_errors("@mutable struct M { long id; };"),
            std::vector<std::string>{"1:1: @mutable types are not read: their parameter-list encodings give members "
                                     "ids a channel's type has not"});
  EXPECT_EQ(idl_errors("union U switch (long) { case 1: long a; };\nstruct S { long x; };"),
            std::vector<std::string>{
                "1:1: unions are not read: a channel's type has no variant fields (ROS 2 generates none)"});
  EXPECT_EQ(idl_errors("struct W { wchar c; wstring s; };"),
            (std::vector<std::string>{"1:12: wide characters (wchar, wstring) are not read: use char and string",
                                      "1:21: wide characters (wchar, wstring) are not read: use char and string"}));
  EXPECT_EQ(idl_errors("struct L { long double d; };"),
            std::vector<std::string>{"1:17: long double is not read: a channel's type has no 128-bit float"});
  EXPECT_EQ(idl_errors("struct F;\nstruct G : F { long x; };"),
            (std::vector<std::string>{"1:1: forward declarations are not read: declare struct F where it is first used",
                                      "2:10: struct inheritance is not read: give struct G its base's members"}));
  EXPECT_EQ(idl_errors("#define X 1\n#pragma keylist K id\n#pragma once\nstruct K { long id; };"),
            (std::vector<std::string>{"1:1: #define is not read: this is no preprocessor (only #include, #pragma "
                                      "and an include guard are read)",
                                      "2:1: #pragma keylist declares keys: keyed types are not read (the gateway "
                                      "does not compute key hashes)"}));
  EXPECT_EQ(idl_errors("module m {\n#include \"a.idl\"\n};"),
            std::vector<std::string>{
                "2:1: an #include inside a module or struct is not read: put it at the top of the file"});
  EXPECT_EQ(
      idl_errors("enum E { @value(1) A, B };\n@bit_bound(8) enum F { C };"),
      std::vector<std::string>{"2:1: @bit_bound other than 32 is not read: an IDL enum is a 32-bit integer here"});
  EXPECT_EQ(idl_errors("struct X { @non_serialized long cache; };\n@extensibility(MUTABLE) struct Y { long y; };\n"
                       "bitmask B { ONE };\nstruct Z { long z; };"),
            (std::vector<std::string>{
                "1:12: @non_serialized members are not read: the type would differ from what goes on the wire",
                "2:1: @mutable types are not read: their parameter-list encodings give members ids a channel's type "
                "has not",
                "3:1: 'bitmask' declarations are not read: only modules, structs, enums, typedefs and constants are"}));
  EXPECT_EQ(idl_errors("struct N { map<long, long> m; any a; };"),
            (std::vector<std::string>{"1:12: maps are not read: a channel's type has no map",
                                      "1:31: 'any' types are not read"}));
}

TEST(IdlTypes, EverySyntaxAndNameProblemIsLocated) {
  EXPECT_EQ(idl_errors("struct S { long a }"),
            (std::vector<std::string>{"1:19: expected ';' after the member, found '}'",
                                      "1:20: expected ';' after the struct's '}', found the end of the text"}));
  EXPECT_EQ(idl_errors("struct S { long a; long a; Nope n; };"),
            (std::vector<std::string>{"1:25: member a declared twice in S",
                                      "1:28: type 'Nope' is not declared before its use"}));
  EXPECT_EQ(idl_errors("struct S { S s; };"),
            std::vector<std::string>{"1:12: struct S contains itself: a channel's type is finite"});
  EXPECT_EQ(idl_errors("module m { struct S { long a; }; };\nmodule m { enum S { X }; };"),
            std::vector<std::string>{"2:12: m::S is declared twice (first as a struct at 1:12)"});
  EXPECT_EQ(idl_errors("const long C = 1;\nstruct S { C c; long a[0]; string<C> s; };"),
            (std::vector<std::string>{"2:12: 'C' is a constant, not a type",
                                      "2:24: an array's size '0' is not a positive integer of 32 bits"}));
  EXPECT_EQ(idl_errors("const octet O = 256;\nconst boolean B = 1;\nconst string<2> S = \"abc\";\nconst long "
                       "E = 1 + 2;\nconst float F = 1e39;"),
            (std::vector<std::string>{
                "1:17: '256' is not a value octet holds", "2:19: expected TRUE or FALSE, found '1'",
                "3:21: the string has 3 characters, more than its bound 2",
                "4:18: expected ';' after the constant's value (a literal: expressions are not read), found '+'",
                "5:17: '1e39' is not a value float holds"}));
  EXPECT_EQ(idl_errors("struct S { long a; }; /* open"),
            std::vector<std::string>{"1:23: unterminated comment: no '*/' before the end of the text"});
  EXPECT_EQ(idl_errors("struct S { @unit(3) long a; @min(\"x\") long b; };"),
            (std::vector<std::string>{"1:12: @unit takes a string: @unit(\"m/s\")",
                                      "1:29: @min's value 'x' is not a number"}));
  EXPECT_EQ(idl_errors("struct T { long a; };\nstruct T { long b; };"),
            std::vector<std::string>{"2:1: T is declared twice (first as a struct at 1:1)"});
}

TEST(IdlTypes, LimitsKeepHostileInputCheap) {
  EXPECT_EQ(parse_idl_types(std::string(kIdlMaxTextBytes + 1, ' ')).errors.at(0).message,
            "the IDL file has 1048577 bytes, more than the limit of 1048576");
  std::string deep;
  for (std::size_t i = 0; i <= kIdlMaxModuleDepth; ++i) deep += "module m {\n";
  EXPECT_EQ(idl_errors(deep).at(0), "17:1: modules nested more than 16 deep");
  // An include chain deeper than the limit.
  const IdlIncludeLoader chain = [](std::string_view name) -> std::optional<std::string> {
    return "#include \"" + std::string(name) + "x\"\n";
  };
  const auto errors = idl_errors("#include \"f\"\n", chain);
  ASSERT_FALSE(errors.empty());
  EXPECT_NE(errors[0].find("more than 16 files including each other"), std::string::npos) << errors[0];
  // Structs used many times over do not expand without limit.
  std::string wide = "struct S0 { long a; };\n";
  for (int level = 1; level <= 4; ++level) {
    wide += "struct S" + std::to_string(level) + " {";
    for (int i = 0; i < 200; ++i) wide += " S" + std::to_string(level - 1) + " m" + std::to_string(i) + ";";
    wide += " };\n";
  }
  const IdlTypeFile file = parse_idl_types(wide);
  ASSERT_TRUE(file.ok());
  const IdlChannelType typed = idl_channel_type(file, *file.find("S4"));
  ASSERT_FALSE(typed.ok());
  EXPECT_NE(typed.errors[0].message.find("expands to more than 65536 types"), std::string::npos);
  // Errors are capped.
  std::string bad;
  for (int i = 0; i < 300; ++i) bad += "struct;\n";
  const IdlTypeFile many = parse_idl_types(bad);
  EXPECT_EQ(many.errors.size(), 101u);
  EXPECT_EQ(many.errors.back().message, "200 more errors not reported");
  // Also when an included file is read while its includer's errors still wait to be reported
  // (fuzz_idl_types found 102 and more).
  const std::string bad_include = bad;
  const IdlIncludeLoader load = [&](std::string_view) -> std::optional<std::string> { return bad_include; };
  const IdlTypeFile nested = parse_idl_types(bad.substr(0, 8 * 150) + "#include \"bad.idl\"\n" + bad, load);
  EXPECT_EQ(nested.errors.size(), 101u);
  EXPECT_NE(nested.errors.back().message.find("more errors not reported"), std::string::npos);
}

// Bytes by hand, little-endian.
class IdlSampleBytes {
 public:
  IdlSampleBytes& u8(std::uint8_t v) { return number(v, 1); }
  IdlSampleBytes& u16(std::uint16_t v) { return number(v, 2); }
  IdlSampleBytes& u32(std::uint32_t v) { return number(v, 4); }
  IdlSampleBytes& f64(double v) { return number(std::bit_cast<std::uint64_t>(v), 8); }
  IdlSampleBytes& text(std::string_view s) {
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    return *this;
  }
  IdlSampleBytes& zeros(std::size_t n) {
    bytes_.insert(bytes_.end(), n, 0);
    return *this;
  }
  std::vector<std::uint8_t> bytes() const { return bytes_; }

 private:
  IdlSampleBytes& number(std::uint64_t v, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  std::vector<std::uint8_t> bytes_;
};

TEST(IdlTypes, AHandSerializedSampleDecodesThroughTheParsedType) {
  const IdlTypeFile file = parse_idl_types(R"idl(module t {
  enum Mode { OFF, ON, FAULT };
  struct Small {
    octet a;
    double b;
    string<8> s;
    sequence<short, 3> q;
    Mode m;
    boolean f;
    char c[2];
  };
};
)idl");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  const IdlChannelType typed = idl_channel_type(file, *file.find("t::Small"));
  ASSERT_TRUE(typed.ok()) << typed.errors.front().message;
  auto cdr = CdrRepresentation::make(typed.type, DdsRepresentation::xcdr1, typed.extensibility);
  ASSERT_TRUE(cdr) << cdr.error().text;
  // XCDR1 little-endian (XTypes 1.3 7.4.3): each primitive aligned to its size from the body's start.
  const std::vector<std::uint8_t> wire = IdlSampleBytes()
                                             .u8(0x00)
                                             .u8(0x01)
                                             .u8(0x00)
                                             .u8(0x00)  // CDR_LE, options 0
                                             .u8(7)
                                             .zeros(7)   // a, then b's alignment
                                             .f64(-2.5)  // b at 8
                                             .u32(3)
                                             .text("hi")
                                             .u8(0)  // s at 16: "hi" and its NUL
                                             .zeros(1)
                                             .u32(2)
                                             .u16(0xFFFF)
                                             .u16(300)  // q at 24: count, -1, 300
                                             .u32(2)    // m at 32: FAULT
                                             .u8(1)     // f at 36
                                             .u8('x')
                                             .u8(0x80)  // c at 37
                                             .zeros(1)  // padding to a multiple of 4
                                             .bytes();
  std::vector<std::uint8_t> wire_padded = wire;
  wire_padded[3] = 1;  // the options count the final padding byte, as Cyclone writes it
  const std::vector<std::uint8_t> event = IdlSampleBytes()
                                              .u8(7)
                                              .f64(-2.5)
                                              .u32(2)
                                              .text("hi")
                                              .u32(2)
                                              .u16(0xFFFF)
                                              .u16(300)
                                              .u32(2)
                                              .u8(1)
                                              .u8('x')
                                              .u8(0x80)
                                              .bytes();
  std::vector<std::uint8_t> compact(cdr.value().max_compact_size());
  const Conversion read = cdr.value().to_compact(wire_padded, compact);
  ASSERT_TRUE(read.ok()) << static_cast<int>(read.fault);
  compact.resize(read.size);
  EXPECT_EQ(compact, event);
  std::vector<std::uint8_t> written(cdr.value().max_wire_size());
  const Conversion write = cdr.value().from_compact(event, written);
  ASSERT_TRUE(write.ok());
  written.resize(write.size);
  EXPECT_EQ(written, wire_padded);
}

}  // namespace
}  // namespace idl_test
}  // namespace cosmic
