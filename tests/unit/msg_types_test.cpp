// ROS 2 .msg files (cosmic/msg_types.hpp): messages as ROS 2 ships them (geometry_msgs/Twist and
// Vector3, std_msgs/Header with builtin_interfaces/Time, sensor_msgs/LaserScan, comments and
// all) read as rosidl reads them, with the channel types whose CDR form is the IDL struct rosidl
// generates (shown by decoding hand-made XCDR1 samples through CdrRepresentation); constants,
// defaults, units, bounded strings and arrays; every refusal located; cycles, missing messages
// and the limits. tests/integration/msg_types checks the same files against rosidl itself.
#include "cosmic/msg_types.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "cosmic/cdr_representation.hpp"

namespace cosmic {
// Its own namespace: unity builds merge test files, whose anonymous helpers must not clash.
namespace msg_types_test {
namespace {

// geometry_msgs, std_msgs and sensor_msgs as ROS 2 (Humble) ships them.
constexpr std::string_view kTwist =
    "# This expresses velocity in free space broken into its linear and angular parts.\n"
    "\n"
    "Vector3  linear\n"
    "Vector3  angular\n";
constexpr std::string_view kVector3 =
    "# This represents a vector in free space.\n"
    "\n"
    "# This is semantically different than a point.\n"
    "# A vector is always anchored at the origin.\n"
    "# When a trasform is applied to a vector only\n"
    "# the rotational component is applied.\n"
    "\n"
    "float64 x\n"
    "float64 y\n"
    "float64 z\n";
constexpr std::string_view kHeader =
    "# Standard metadata for higher-level stamped data types.\n"
    "# This is generally used to communicate timestamped data\n"
    "# in a particular coordinate frame.\n"
    "\n"
    "# Two-integer timestamp that is expressed as seconds and nanoseconds.\n"
    "builtin_interfaces/Time stamp\n"
    "\n"
    "# Transform frame with which this data is associated.\n"
    "string frame_id\n";
constexpr std::string_view kLaserScan =
    "# Single scan from a planar laser range-finder\n"
    "#\n"
    "# If you have another ranging device with different behavior (e.g. a sonar\n"
    "# array), please find or create a different message, since applications\n"
    "# will make fairly laser-specific assumptions about this data\n"
    "\n"
    "std_msgs/Header header # timestamp in the header is the acquisition time of\n"
    "                             # the first ray in the scan.\n"
    "                             #\n"
    "                             # in frame frame_id, angles are measured around\n"
    "                             # the positive Z axis (counterclockwise, if Z is up)\n"
    "                             # with zero angle being forward along the x axis\n"
    "\n"
    "float32 angle_min            # start angle of the scan [rad]\n"
    "float32 angle_max            # end angle of the scan [rad]\n"
    "float32 angle_increment      # angular distance between measurements [rad]\n"
    "\n"
    "float32 time_increment       # time between measurements [seconds] - if your scanner\n"
    "                             # is moving, this will be used in interpolating position\n"
    "                             # of 3d points\n"
    "float32 scan_time            # time between scans [seconds]\n"
    "\n"
    "float32 range_min            # minimum range value [m]\n"
    "float32 range_max            # maximum range value [m]\n"
    "\n"
    "float32[] ranges             # range data [m]\n"
    "                             # (Note: values < range_min or > range_max should be discarded)\n"
    "float32[] intensities        # intensity data [device-specific units].  If your\n"
    "                             # device does not provide intensities, please leave\n"
    "                             # the array empty.\n";

using MsgTexts = std::map<std::string, std::string>;  // "pkg/Name" -> text

MsgTexts ros2_texts() {
  return {{"geometry_msgs/Twist", std::string(kTwist)},
          {"geometry_msgs/Vector3", std::string(kVector3)},
          {"std_msgs/Header", std::string(kHeader)},
          {"sensor_msgs/LaserScan", std::string(kLaserScan)}};
}

// A loader over `texts` that counts what it was asked.
MsgLoader msg_loader(const MsgTexts& texts, std::vector<std::string>* asked = nullptr) {
  return [&texts, asked](const std::string& package, const std::string& name) -> std::optional<std::string> {
    if (asked != nullptr) asked->push_back(package + "/" + name);
    const auto it = texts.find(package + "/" + name);
    if (it == texts.end()) return std::nullopt;
    return it->second;
  };
}

MsgChannelType msg_resolve(const MsgTexts& texts, const std::string& full,
                           const std::map<std::string, std::uint32_t>& max_length = {}) {
  const auto slash = full.find('/');
  return msg_channel_type(full.substr(0, slash), full.substr(slash + 1), msg_loader(texts), max_length);
}

std::vector<std::string> msg_parse_errors(std::string_view text) {
  std::vector<std::string> out;
  for (const MsgError& e : parse_msg(text).errors)
    out.push_back(std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  return out;
}

std::vector<std::string> msg_type_errors(const MsgChannelType& typed) {
  std::vector<std::string> out;
  for (const MsgTypeError& e : typed.errors)
    out.push_back(e.file + ":" + std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  return out;
}

TEST(MsgTypes, TwistAndVector3) {
  std::vector<std::string> asked;
  const MsgTexts texts = ros2_texts();
  const MsgChannelType typed = msg_channel_type("geometry_msgs", "Twist", msg_loader(texts, &asked));
  ASSERT_TRUE(typed.ok()) << msg_type_errors(typed).front();
  EXPECT_EQ(describe(typed.type),
            "{linear: {x: float64, y: float64, z: float64}, angular: {x: float64, y: float64, z: float64}}");
  // Vector3 is read once, though used twice; a bare name is a message of the same package.
  EXPECT_EQ(asked, (std::vector<std::string>{"geometry_msgs/Twist", "geometry_msgs/Vector3"}));
  EXPECT_EQ(typed.files,
            (std::vector<MsgSourceFile>{{"geometry_msgs/msg/Twist", false}, {"geometry_msgs/msg/Vector3", false}}));
  const MsgFile twist = parse_msg(kTwist);
  ASSERT_EQ(twist.fields.size(), 2u);
  EXPECT_EQ(twist.fields[1].name, "angular");
  EXPECT_EQ(twist.fields[1].type, (MsgFieldType{"", "Vector3", 0, MsgFieldType::Array::none, 0}));
  EXPECT_EQ(twist.fields[1].line, 4);
}

TEST(MsgTypes, HeaderWithTheBuiltInTime) {
  const MsgTexts texts = ros2_texts();  // no builtin_interfaces on the type path
  const MsgChannelType typed = msg_resolve(texts, "std_msgs/Header");
  ASSERT_TRUE(typed.ok()) << msg_type_errors(typed).front();
  EXPECT_EQ(describe(typed.type), "{stamp: {sec: int32, nanosec: uint32}, frame_id: string<=65536>}");
  EXPECT_EQ(typed.files,
            (std::vector<MsgSourceFile>{{"std_msgs/msg/Header", false}, {"builtin_interfaces/msg/Time", true}}));
  EXPECT_EQ(describe(msg_resolve(texts, "std_msgs/Header", {{"frame_id", 64}}).type),
            "{stamp: {sec: int32, nanosec: uint32}, frame_id: string<=64>}");
  // A Time on the type path is the one read; Duration is built in too.
  MsgTexts own = texts;
  own["builtin_interfaces/Time"] = "int64 sec\n";
  EXPECT_EQ(describe(msg_resolve(own, "std_msgs/Header").type), "{stamp: {sec: int64}, frame_id: string<=65536>}");
  EXPECT_EQ(describe(msg_resolve({}, "builtin_interfaces/Duration").type), "{sec: int32, nanosec: uint32}");
  EXPECT_FALSE(msg_builtin_text("builtin_interfaces", "Clock"));
  EXPECT_TRUE(parse_msg(*msg_builtin_text("builtin_interfaces", "Time")).ok());
}

TEST(MsgTypes, LaserScanWithUnitsAndBounds) {
  const MsgTexts texts = ros2_texts();
  const MsgChannelType typed =
      msg_resolve(texts, "sensor_msgs/LaserScan", {{"ranges", 1081}, {"intensities", 1081}, {"header.frame_id", 64}});
  ASSERT_TRUE(typed.ok()) << msg_type_errors(typed).front();
  EXPECT_EQ(describe(typed.type),
            "{header: {stamp: {sec: int32, nanosec: uint32}, frame_id: string<=64>}, angle_min: float32 [rad], "
            "angle_max: float32 [rad], angle_increment: float32 [rad], time_increment: float32 [seconds], "
            "scan_time: float32 [seconds], range_min: float32 [m], range_max: float32 [m], ranges: "
            "sequence<float32, 1081> [m], intensities: sequence<float32, 1081> [device-specific units]}");
  // Unbounded, the two sequences hold more scalars than a channel's type may.
  EXPECT_EQ(msg_type_errors(msg_resolve(texts, "sensor_msgs/LaserScan")),
            std::vector<std::string>{"sensor_msgs/msg/LaserScan:0:0: its largest value holds more than 65536 scalars "
                                     "(max_length: {PATH: N} bounds an unbounded sequence)"});
}

TEST(MsgTypes, ConstantsDefaultsAndComments) {
  const MsgFile file = parse_msg(
      "# file comment [not a unit]\n"
      "int32 FOO=1\n"
      "uint8 BAR = 0xff   # hex, as Python's int(text, 0)\n"
      "string NAME=\"a b\"\n"
      "float64 PI=3.14159\n"
      "bool YES=True\n"
      "# the speed [m/s]\n"
      "float64 speed 5.5\n"
      "int32[3] triple [1, 2, 3]\n"
      "string<=8 label 'x y'\n"
      "string[] names [\"a,b\", 'c']\n"
      "int8 small -128\n"
      "bool flag\n"
      "  # [K]  (an indented comment: flag's)\n");
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  ASSERT_EQ(file.constants.size(), 5u);
  EXPECT_EQ(file.constants[1], (MsgConstant{"uint8", "BAR", "0xff", 3, 1}));
  EXPECT_EQ(file.constants[2].value, "\"a b\"");
  ASSERT_EQ(file.fields.size(), 6u);
  EXPECT_EQ(file.fields[0].default_value, "5.5");
  EXPECT_EQ(file.fields[0].unit, "m/s");
  EXPECT_EQ(file.fields[1].default_value, "[1, 2, 3]");
  EXPECT_EQ(file.fields[2].type, (MsgFieldType{"", "string", 8, MsgFieldType::Array::none, 0}));
  EXPECT_EQ(file.fields[3].default_value, "[\"a,b\", 'c']");
  EXPECT_EQ(file.fields[5].default_value, std::nullopt);
  EXPECT_EQ(file.fields[5].unit, "K");
  // Constants are not fields; defaults change no type.
  const MsgChannelType typed = msg_resolve({{"p/M", "int32 A=1\nint32 a 7\n"}}, "p/M");
  EXPECT_EQ(describe(typed.type), "{a: int32}");
  // Two bracketed words are no unit (rosidl's rule); a unit on a string is not a channel's.
  const MsgFile two = parse_msg("float32 x # [m] or [ft]\nstring s # [m]\n");
  EXPECT_EQ(two.fields[0].unit, "");
  EXPECT_EQ(describe(msg_resolve({{"p/M", "string s # [m]\n"}}, "p/M").type), "{s: string<=65536>}");
}

TEST(MsgTypes, EveryPrimitiveBoundedStringsAndArrays) {
  const MsgChannelType typed = msg_resolve(
      {{"p/All",
        "bool a\nbyte b\nchar c\nint8 d\nuint8 e\nint16 f\nuint16 g\nint32 h\nuint32 i\nint64 j\nuint64 k\n"
        "float32 l\nfloat64 m\nstring n\nstring<=10 o\nint32[4] p\nint32[<=5] q\nbyte[] r\nstring<=8[<=4] s\n"
        "string[2] t\nPart[2] u\nPart[<=3] v\n"},
       {"p/Part", "uint8 w\n"}},
      "p/All", {{"r", 1024}, {"t[]", 16}});
  ASSERT_TRUE(typed.ok()) << msg_type_errors(typed).front();
  EXPECT_EQ(describe(typed.type),
            "{a: bool, b: uint8, c: uint8, d: int8, e: uint8, f: int16, g: uint16, h: int32, i: uint32, j: int64, k: "
            "uint64, l: float32, m: float64, n: string<=65536>, o: string<=10>, p: int32[4], q: sequence<int32, 5>, r: "
            "sequence<uint8, 1024>, s: sequence<string<=8>, 4>, t: string<=16>[2], u: {w: uint8}[2], v: "
            "sequence<{w: uint8}, 3>}");
}

TEST(MsgTypes, AMessageWithoutFieldsIsRosidlsPlaceholder) {
  const MsgChannelType typed = msg_resolve({{"std_msgs/Empty", ""}, {"p/M", "std_msgs/Empty e\nint32 X=1\n"}}, "p/M");
  ASSERT_TRUE(typed.ok());
  EXPECT_EQ(describe(typed.type), "{e: {structure_needs_at_least_one_member: uint8}}");
  EXPECT_EQ(describe(msg_resolve({{"p/C", "int32 ONLY=1\n"}}, "p/C").type),
            "{structure_needs_at_least_one_member: uint8}");
}

TEST(MsgTypes, EveryRefusalIsLocated) {
  EXPECT_EQ(msg_parse_errors("wstring w\n"),
            std::vector<std::string>{"1:1: wstring is refused: a channel's strings are bytes, and a wide string's CDR "
                                     "form changed between DDS-XTypes 1.1 and 1.2 (DDS implementations disagree on "
                                     "it); use string"});
  EXPECT_EQ(msg_parse_errors("int8 a\ntime t\nduration[] d\n"),
            (std::vector<std::string>{"2:1: ROS 1's time is not a ROS 2 type: write builtin_interfaces/Time",
                                      "3:1: ROS 1's duration is not a ROS 2 type: write builtin_interfaces/Duration"}));
  EXPECT_EQ(msg_parse_errors("int32[0] a\nint32[<=70000] b\nstring<=x c\nint32[2][3] d\nint32] e\n"),
            (std::vector<std::string>{"1:7: array size '0' is not a whole number above 0",
                                      "2:9: array size 70000 is beyond 65536, the most a channel's type holds",
                                      "3:9: string bound 'x' is not a whole number above 0",
                                      "4:1: type 'int32[2][3]': ROS 2 has no arrays of arrays",
                                      "5:1: type 'int32]' ends with ']' but has no '['"}));
  EXPECT_EQ(msg_parse_errors("float x\ngeometry_msgs/msg/Point p\nBad_Pkg/Point q\npkg/point r\n"),
            (std::vector<std::string>{
                "1:1: 'float' is neither a primitive type (bool, byte, char, float32, float64, int8..uint64, string) "
                "nor a message name ([A-Z][A-Za-z0-9]*)",
                "2:1: type 'geometry_msgs/msg/Point': a .msg file names a message pkg/Name (rosidl reads no /msg/ "
                "there)",
                "3:1: 'Bad_Pkg' is not a package name ([a-z][a-z0-9_]*, no '__', no final '_')",
                "4:5: 'point' is not a message name ([A-Z][A-Za-z0-9]*)"}));
  EXPECT_EQ(msg_parse_errors("int32 Speed\nint32 a__b\nint32 x\nint32 x\nint32\n  int32 y\n"),
            (std::vector<std::string>{"1:7: 'Speed' is not a field name ([a-z][a-z0-9_]*, no '__', no final '_')",
                                      "2:7: 'a__b' is not a field name ([a-z][a-z0-9_]*, no '__', no final '_')",
                                      "4:7: field x defined twice", "5:6: expected a name after the type 'int32'",
                                      "6:1: a definition starts at the beginning of its line (rosidl refuses an "
                                      "indented one)"}));
  EXPECT_EQ(
      msg_parse_errors("int32 foo=1\nint8 BIG=128\nuint8 NEG=-1\nint32[2] ARR=1\nbool B=yes\nint32 B_=1\n"
                       "float64 F=x\nint32 D=1\nint32 D=2\nstring S=\"a\"b\"\n"),
      (std::vector<std::string>{
          "1:7: 'foo' is not a constant name ([A-Z][A-Z0-9_]*, no '__', no final '_')",
          "2:10: value '128' is not an integer -128..127 (int8)", "3:11: value '-1' is not an integer 0..255 (uint8)",
          "4:1: a constant's type is bool, byte, char, float32, float64, int8..uint64 or string, not "
          "'int32[2]'",
          "5:8: value 'yes' is not a bool (true, false, 1 or 0)",
          "6:7: 'B_' is not a constant name ([A-Z][A-Z0-9_]*, no '__', no final '_')",
          "7:11: value 'x' is not a floating point number", "9:7: constant D defined twice",
          "10:10: string '\"a\"b\"': a quote inside it is not escaped"}));
  EXPECT_EQ(
      msg_parse_errors("int32[2] a [1]\nint32[<=1] b [1, 2]\nint32[] c 1\nstring<=2 d abc\nVector3 v 0\n"
                       "char e 256\nint64 f 0x\n"),
      (std::vector<std::string>{
          "1:12: the array needs exactly 2 values, not 1", "2:14: the array holds at most 1 values, not 2",
          "3:11: an array's default value '1' is written [A, B, ...]", "4:13: string 'abc' is longer than its bound 2",
          "5:11: a field of a message type has no default value", "6:8: value '256' is not an integer 0..255 (char)",
          "7:9: value '0x' is not an integer -9223372036854775808..9223372036854775807 "
          "(int64)"}));
  EXPECT_EQ(msg_parse_errors(std::string("int32 a\x01\n# \x01 in a comment is fine\n")),
            std::vector<std::string>{"1:8: a control character (byte 1) in a definition"});
  EXPECT_EQ(msg_parse_errors(std::string(kMsgMaxTextBytes + 1, '#')).at(0),
            "0:0: the .msg file has 1048577 bytes, more than the limit of 1048576");
}

TEST(MsgTypes, ErrorsAreCappedAndCounted) {
  std::string text;
  for (int i = 0; i < 150; ++i) text += "float x" + std::to_string(i) + "\n";
  const auto errors = msg_parse_errors(text);
  ASSERT_EQ(errors.size(), 101u);
  EXPECT_EQ(errors.back(), "0:0: 50 more errors not reported");
}

TEST(MsgTypes, ErrorsOfADependencyAreLocatedInIt) {
  const MsgChannelType typed =
      msg_resolve({{"p/Outer", "# outer\nInner inner\n"}, {"p/Inner", "int32 ok\nfloat bad\n"}}, "p/Outer");
  EXPECT_EQ(msg_type_errors(typed),
            std::vector<std::string>{"p/msg/Inner:2:1: 'float' is neither a primitive type (bool, byte, char, "
                                     "float32, float64, int8..uint64, string) nor a message name ([A-Z][A-Za-z0-9]*)"});
}

TEST(MsgTypes, MissingMessagesAndTheBareHeader) {
  EXPECT_EQ(msg_type_errors(msg_resolve({}, "p/Nothing")),
            std::vector<std::string>{"p/msg/Nothing:0:0: p/msg/Nothing not found on the type path"});
  EXPECT_EQ(msg_type_errors(msg_resolve({{"p/M", "int8 a\nHeader header\nother_pkg/Gone g\n"}}, "p/M")),
            (std::vector<std::string>{"p/msg/M:2:1: p/msg/Header not found on the type path (a bare Header is "
                                      "p/Header in ROS 2: write std_msgs/Header)",
                                      "p/msg/M:3:1: other_pkg/msg/Gone not found on the type path"}));
  // A package's own Header is what a bare Header means.
  EXPECT_EQ(describe(msg_resolve({{"p/M", "Header h\n"}, {"p/Header", "uint32 seq\n"}}, "p/M").type),
            "{h: {seq: uint32}}");
  EXPECT_EQ(msg_type_errors(msg_channel_type("P", "m", msg_loader({}))),
            std::vector<std::string>{
                "P/msg/m:0:0: not a ROS 2 message name: package [a-z][a-z0-9_]*, message [A-Z][A-Za-z0-9]*"});
}

TEST(MsgTypes, CyclesDepthAndSize) {
  EXPECT_EQ(msg_type_errors(msg_resolve({{"p/A", "B b\n"}, {"p/B", "int8 x\nA[] a\n"}}, "p/A")),
            std::vector<std::string>{"p/msg/B:2:1: a message cannot contain itself: p/msg/A -> p/msg/B -> p/msg/A"});
  EXPECT_EQ(msg_type_errors(msg_resolve({{"p/A", "A a\n"}}, "p/A")),
            std::vector<std::string>{"p/msg/A:1:1: a message cannot contain itself: p/msg/A -> p/msg/A"});
  // L0 contains L1 ... contains L8: L7's field next is 7 deep, so L8's fields would be 8.
  MsgTexts chain;
  for (int i = 0; i < 9; ++i)
    chain["p/L" + std::to_string(i)] = i < 8 ? "L" + std::to_string(i + 1) + " next\n" : "int8 x\n";
  EXPECT_EQ(
      msg_type_errors(msg_resolve(chain, "p/L0")),
      std::vector<std::string>{"p/msg/L7:1:1: field next is nested more than 8 levels deep (messages and arrays)"});
  EXPECT_TRUE(msg_resolve(chain, "p/L1").ok());
  // 200 fields of 200 fields of 200: more than a type may expand to, refused early.
  MsgTexts wide;
  for (const std::string level : {"A", "B", "C"}) {
    std::string text;
    for (int i = 0; i < 200; ++i)
      text += (level == "C" ? std::string("int8") : level == "A" ? "B" : "C") + " f" + std::to_string(i) + "\n";
    wide["p/" + level] = text;
  }
  EXPECT_EQ(msg_type_errors(msg_resolve(wide, "p/A")),
            std::vector<std::string>{
                "p/msg/A:0:0: the type expands to more than 65536 fields (messages used many times over)"});
  // More messages than one type may read.
  MsgTexts many;
  std::string root;
  for (std::size_t i = 0; i < kMsgMaxFiles; ++i) {
    root += "M" + std::to_string(i) + " f" + std::to_string(i) + "\n";
    many["p/M" + std::to_string(i)] = "int8 x\n";
  }
  many["p/Root"] = root;
  const auto errors = msg_type_errors(msg_resolve(many, "p/Root"));
  EXPECT_EQ(errors, std::vector<std::string>{"p/msg/Root:256:1: more than 256 messages in one type"});
}

TEST(MsgTypes, MaxLengthPaths) {
  const MsgTexts texts = {{"p/M", "string[] names\nPoint[] points\nstring<=4 fixed\n"},
                          {"p/Point", "string label\nfloat64 x\n"}};
  const MsgChannelType typed =
      msg_resolve(texts, "p/M", {{"names", 10}, {"names[]", 32}, {"points", 5}, {"points[].label", 16}});
  ASSERT_TRUE(typed.ok()) << msg_type_errors(typed).front();
  EXPECT_EQ(describe(typed.type),
            "{names: sequence<string<=32>, 10>, points: sequence<{label: string<=16>, x: float64}, 5>, fixed: "
            "string<=4>}");
  EXPECT_EQ(msg_type_errors(msg_resolve(texts, "p/M", {{"fixed", 2}, {"points.label", 3}, {"names", 0}})),
            (std::vector<std::string>{"p/msg/M:1:1: max_length 0 of names is not 1..65536"}));
  EXPECT_EQ(msg_type_errors(msg_resolve(texts, "p/M", {{"fixed", 2}, {"points.label", 3}})),
            (std::vector<std::string>{
                "p/msg/M:0:0: max_length names 'fixed', which is not an unbounded string or sequence of p/msg/M (a "
                "path: field names joined by '.', \"[]\" to step into an array's elements)",
                "p/msg/M:0:0: max_length names 'points.label', which is not an unbounded string or sequence of p/msg/M "
                "(a path: field names joined by '.', \"[]\" to step into an array's elements)"}));
}

TEST(MsgTypes, TypeNames) {
  EXPECT_EQ(msg_type_name("geometry_msgs/msg/Twist"), (MsgTypeName{"geometry_msgs", "Twist"}));
  EXPECT_EQ(msg_type_name("geometry_msgs/Twist"), (MsgTypeName{"geometry_msgs", "Twist"}));
  EXPECT_EQ(msg_type_name("geometry_msgs/Twist")->full(), "geometry_msgs/msg/Twist");
  EXPECT_FALSE(msg_type_name("Twist"));
  EXPECT_FALSE(msg_type_name("geometry_msgs/srv/Twist"));
  EXPECT_FALSE(msg_type_name("Geometry/Twist"));
}

// Little-endian bytes by hand.
std::vector<std::uint8_t> msg_le(std::vector<std::uint8_t> bytes, std::uint64_t value, std::size_t size) {
  for (std::size_t i = 0; i < size; ++i) bytes.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  return bytes;
}

template <typename T>
T msg_read(const std::vector<std::uint8_t>& bytes, std::size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof value);
  return value;
}

std::vector<std::uint8_t> msg_to_compact(const ChannelType& type, const std::vector<std::uint8_t>& wire) {
  const auto cdr = CdrRepresentation::make(type, DdsRepresentation::xcdr1, CdrExtensibility::final_type);
  EXPECT_TRUE(cdr.ok());
  std::vector<std::uint8_t> compact(cdr.value().max_compact_size());
  const Conversion c = cdr.value().to_compact(wire, compact);
  EXPECT_TRUE(c.ok()) << static_cast<int>(c.fault);
  compact.resize(c.size);
  return compact;
}

TEST(MsgTypes, TheTypesCdrFormIsRos2s) {
  const MsgTexts texts = ros2_texts();
  // A Twist as rmw writes it: the XCDR1 little-endian header, then six doubles.
  std::vector<std::uint8_t> twist = {0x00, 0x01, 0x00, 0x00};
  const double values[6] = {0.5, -1.25, 2.0, 0.0, 0.125, -3.5};
  for (const double v : values) twist = msg_le(twist, std::bit_cast<std::uint64_t>(v), 8);
  const MsgChannelType twist_type = msg_resolve(texts, "geometry_msgs/Twist");
  ASSERT_TRUE(twist_type.ok());
  const auto compact = msg_to_compact(twist_type.type, twist);
  ASSERT_EQ(compact.size(), 48u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(msg_read<double>(compact, 8 * i), values[i]);

  // A Header: int32 sec, uint32 nanosec, then the string with its length (NUL counted) and NUL,
  // padded to a multiple of 4 with the padding announced in the options (as Cyclone DDS writes).
  std::vector<std::uint8_t> header = {0x00, 0x01, 0x00, 0x02};
  header = msg_le(header, static_cast<std::uint32_t>(-7), 4);
  header = msg_le(header, 999'999'999, 4);
  header = msg_le(header, 10, 4);
  for (const char c : std::string("base_link")) header.push_back(static_cast<std::uint8_t>(c));
  header.insert(header.end(), {0, 0, 0});  // NUL, padding
  const MsgChannelType header_type = msg_resolve(texts, "std_msgs/Header");
  ASSERT_TRUE(header_type.ok());
  const auto fields = msg_to_compact(header_type.type, header);
  ASSERT_EQ(fields.size(), 4u + 4 + 4 + 9);
  EXPECT_EQ(msg_read<std::int32_t>(fields, 0), -7);
  EXPECT_EQ(msg_read<std::uint32_t>(fields, 4), 999'999'999u);
  EXPECT_EQ(msg_read<std::uint32_t>(fields, 8), 9u);
  EXPECT_EQ(std::string(fields.begin() + 12, fields.end()), "base_link");
}

}  // namespace
}  // namespace msg_types_test
}  // namespace cosmic
