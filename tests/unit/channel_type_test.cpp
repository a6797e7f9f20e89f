// A channel's type (issue 35 item 1): the model's checks and text (cosmic/channel_type.hpp) and the
// `type:` of the YAML, inline or from a DBC message: every kind read, every problem located (in the
// DBC file where it is there), written back unchanged.
#include <gtest/gtest.h>

#include <string>

#include "cosmic/build_paths.hpp"
#include "cosmic/channel_type.hpp"
#include "cosmic/hop_representation.hpp"
#include "cosmic/config_loader.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace cosmic {
namespace {

FieldType scalar(ScalarKind kind) {
  FieldType t;
  t.scalar = kind;
  return t;
}

TypeField field(std::string name, FieldType type) {
  TypeField f;
  f.name = std::move(name);
  f.type = std::move(type);
  return f;
}

std::string problems_text(const std::vector<TypeProblem>& problems) {
  std::string out;
  for (const auto& p : problems) out += p.where + ": " + p.what + "\n";
  return out;
}

TEST(ChannelType, ScalarNamesAndLimits) {
  EXPECT_EQ(scalar_kind("uint16"), ScalarKind::uint16);
  EXPECT_EQ(scalar_kind("float"), std::nullopt);
  EXPECT_EQ(scalar_name(ScalarKind::boolean), "bool");
  EXPECT_EQ(scalar_limits(ScalarKind::int8), std::make_pair(-128.0, 127.0));
  EXPECT_TRUE(is_integer(ScalarKind::uint64));
  EXPECT_FALSE(is_integer(ScalarKind::float32));
  EXPECT_TRUE(is_signed_integer(ScalarKind::int16));
  EXPECT_FALSE(is_signed_integer(ScalarKind::uint16));
}

TEST(ChannelType, ASoundTypeHasNoProblemAndDescribesItself) {
  ChannelType type;
  TypeField distance = field("distance", scalar(ScalarKind::float32));
  distance.unit = "m";
  distance.minimum = 0;
  distance.maximum = 40.5;
  FieldType state;
  state.kind = FieldType::Kind::enumeration;
  state.scalar = ScalarKind::uint8;
  state.values = {{"OFF", 0}, {"ON", 1}};
  FieldType ranges;
  ranges.kind = FieldType::Kind::array;
  ranges.bound = 4;
  ranges.element = {scalar(ScalarKind::uint8)};
  FieldType track;
  track.kind = FieldType::Kind::sequence;
  track.bound = 10;
  FieldType point;
  point.kind = FieldType::Kind::record;
  point.fields = {field("x", scalar(ScalarKind::float64)), field("y", scalar(ScalarKind::float64))};
  track.element = {point};
  FieldType label;
  label.kind = FieldType::Kind::string;
  label.bound = 32;
  type.fields = {distance, field("state", state), field("ranges", ranges), field("track", track),
                 field("label", label)};
  EXPECT_EQ(check_type(type), std::vector<TypeProblem>{});
  EXPECT_EQ(describe(type),
            "{distance: float32 [m, 0..40.5], state: enum uint8 {OFF=0, ON=1}, ranges: uint8[4], "
            "track: sequence<{x: float64, y: float64}, 10>, label: string<=32>}");
}

TEST(ChannelType, EveryProblemIsNamedWithWhereItIs) {
  ChannelType type;
  TypeField reversed = field("speed", scalar(ScalarKind::int8));
  reversed.minimum = 10;
  reversed.maximum = -10;
  TypeField too_wide = field("count", scalar(ScalarKind::uint8));
  too_wide.maximum = 300;
  FieldType mode;
  mode.kind = FieldType::Kind::enumeration;
  mode.scalar = ScalarKind::uint8;
  mode.values = {{"A", 1}, {"B", 1}, {"C", 256}};
  TypeField unit_on_text = field("name", FieldType{FieldType::Kind::string, ScalarKind::float64, {}, 8, {}, {}});
  unit_on_text.unit = "m";
  FieldType inner;
  inner.kind = FieldType::Kind::record;
  inner.fields = {field("x", scalar(ScalarKind::float64)), field("x", scalar(ScalarKind::float64))};
  type.fields = {reversed,
                 too_wide,
                 field("mode", mode),
                 unit_on_text,
                 field("pose", inner),
                 field("9lives", scalar(ScalarKind::boolean))};
  const std::string text = problems_text(check_type(type));
  EXPECT_NE(text.find("speed: min 10 is above max -10"), std::string::npos) << text;
  EXPECT_NE(text.find("count: max 300 is outside what uint8 holds (0..255)"), std::string::npos) << text;
  EXPECT_NE(text.find("mode: value 1 named twice"), std::string::npos) << text;
  EXPECT_NE(text.find("mode: value C = 256 does not fit uint8"), std::string::npos) << text;
  EXPECT_NE(text.find("name: a unit and a range belong to numeric fields only"), std::string::npos) << text;
  EXPECT_NE(text.find("pose.fields[1]: field 'x' defined twice"), std::string::npos) << text;
  EXPECT_NE(text.find("field name '9lives' is not"), std::string::npos) << text;
}

TEST(ChannelType, NestingAndSizeAreBounded) {
  FieldType deep = scalar(ScalarKind::uint8);
  for (std::size_t i = 0; i < kMaxTypeDepth + 1; ++i) {
    FieldType record;
    record.kind = FieldType::Kind::record;
    record.fields = {field("inner", deep)};
    deep = record;
  }
  ChannelType nested{{field("outer", deep)}, {}};
  EXPECT_NE(problems_text(check_type(nested)).find("nested more than 8 levels deep"), std::string::npos);

  FieldType big;
  big.kind = FieldType::Kind::array;
  big.bound = kMaxTypeBound;
  FieldType row;
  row.kind = FieldType::Kind::array;
  row.bound = 2;
  row.element = {scalar(ScalarKind::uint8)};
  big.element = {row};
  ChannelType huge{{field("grid", big)}, {}};
  EXPECT_NE(problems_text(check_type(huge)).find("more than 65536 scalars"), std::string::npos)
      << problems_text(check_type(huge));
}

// ------------------------------------------------------------------------------ YAML

constexpr const char* kTypedConfigHead =
    "gateway: {name: gw, can_node_id: 1}\n"
    "segments:\n"
    "  - {name: lan, type: dds, domain: 0}\n"
    "  - {name: viz, type: lcm, url: \"udpm://239.255.76.67:7667?ttl=0\"}\n"
    "channels:\n"
    "  - name: scan\n"
    "    subject: 0x10\n"
    "    class: nrt\n"
    "    omission_degree: 0\n"  // (a typed channel's payload comes from its hops)
    "    publishers: [lan]\n"
    "    subscribers: [viz]\n";

std::string listed_errors(const std::vector<ConfigError>& errors) {
  std::string out;
  for (const auto& e : errors) out += e.to_string() + "\n";
  return out;
}

TEST(ChannelTypeYaml, EveryKindIsReadAndWrittenBackUnchanged) {
  const std::string text =
      std::string(kTypedConfigHead) +
      "    type:\n"
      "      fields:\n"
      "        - {name: distance, type: float32, unit: m, min: 0, max: 40.25}\n"
      "        - {name: state, type: enum, underlying: uint8, values: {OFF: 0, ON: 1, FAULT: 7}}\n"
      "        - {name: label, type: string, max_length: 32}\n"
      "        - {name: ranges, type: array, length: 16, element: float32, unit: m, min: -1e3}\n"
      "        - name: track\n"
      "          type: sequence\n"
      "          max_length: 100\n"
      "          element: {type: record, fields: [{name: x, type: float64}, {name: y, type: int64}]}\n"
      "        - {name: pose, type: record, fields: [{name: yaw, type: float64, unit: rad}]}\n"
      "        - {name: ok, type: bool}\n";
  const ConfigResult r = parse_config(text, "typed.yaml");
  ASSERT_TRUE(r.ok()) << listed_errors(r.errors);
  const ChannelSpec& scan = r.config.channels.at(0);
  ASSERT_TRUE(scan.type.has_value());
  EXPECT_EQ(describe(*scan.type),
            "{distance: float32 [m, 0..40.25], state: enum uint8 {OFF=0, ON=1, FAULT=7}, label: string<=32>, "
            "ranges: float32[16] [m, -1000..], track: sequence<{x: float64, y: int64}, 100>, "
            "pose: {yaw: float64 [rad]}, ok: bool}");
  // What bind and the state file write reads back equal.
  const ChannelsResult again = parse_channels("[" + channel_to_yaml(scan) + "]", "bind", r.config);
  ASSERT_TRUE(again.ok()) << listed_errors(again.errors) << channel_to_yaml(scan);
  ASSERT_EQ(again.channels.size(), 1u);
  EXPECT_EQ(again.channels[0], scan) << channel_to_yaml(scan);
}

TEST(ChannelTypeYaml, AChannelWithoutATypeHasNone) {
  const ConfigResult r = parse_config(kTypedConfigHead, "untyped.yaml");
  ASSERT_TRUE(r.ok()) << listed_errors(r.errors);
  EXPECT_FALSE(r.config.channels.at(0).type.has_value());
}

TEST(ChannelTypeYaml, EveryProblemIsLocatedAtOnce) {
  const std::string text = std::string(kTypedConfigHead) +
                           "    type:\n"
                           "      fields:\n"
                           "        - {name: a, type: float16}\n"                              // line 14
                           "        - {name: b, type: uint8, max: 256}\n"                      // line 15
                           "        - {name: c, type: string}\n"                               // line 16
                           "        - {name: d, type: array, max_length: 3, element: int8}\n"  // line 17
                           "        - {name: b, type: bool}\n"                                 // line 18
                           "        - {type: int8}\n"                                          // line 19
                           "        - {name: e, type: enum, values: {X: 1.5}}\n";              // line 20
  const ConfigResult r = parse_config(text, "bad.yaml");
  ASSERT_FALSE(r.ok());
  const std::string errors = listed_errors(r.errors);
  EXPECT_NE(errors.find("bad.yaml:14:27: channels[0].type.fields[0].type: unknown type 'float16'"), std::string::npos)
      << errors;
  EXPECT_NE(errors.find("bad.yaml:16:11: channels[0].type.fields[2]: needs max_length"), std::string::npos) << errors;
  EXPECT_NE(
      errors.find("bad.yaml:17:46: channels[0].type.fields[3].max_length: max_length does not belong to this type"),
      std::string::npos)
      << errors;
  EXPECT_NE(errors.find("bad.yaml:17:11: channels[0].type.fields[3]: needs length"), std::string::npos) << errors;
  EXPECT_NE(errors.find("bad.yaml:19:11: channels[0].type.fields[5]: a field needs a name"), std::string::npos)
      << errors;
  EXPECT_NE(errors.find("channels[0].type.fields[6].values.X: '1.5' is not a whole number"), std::string::npos)
      << errors;
  // Found by the whole-type check once each field reads: only when nothing else is wrong.
  const std::string fixed = std::string(kTypedConfigHead) +
                            "    type:\n"
                            "      fields:\n"
                            "        - {name: b, type: uint8, max: 256}\n"  // line 14
                            "        - {name: b, type: bool}\n";            // line 15
  const ConfigResult r2 = parse_config(fixed, "bad.yaml");
  const std::string errors2 = listed_errors(r2.errors);
  EXPECT_NE(errors2.find("bad.yaml:14:11: channels[0].type.fields[0]: max 256 is outside what uint8 holds (0..255)"),
            std::string::npos)
      << errors2;
  EXPECT_NE(errors2.find("bad.yaml:15:11: channels[0].type.fields[1]: field 'b' defined twice"), std::string::npos)
      << errors2;
}

TEST(ChannelTypeYaml, ADbcMessageGivesTheFieldsAndIsWrittenBackAsItsSource) {
  const std::string text = std::string(kTypedConfigHead) + "    type: {dbc: body.dbc, message: WheelSpeeds}\n";
  const std::string config_path = std::string(build_paths::dbc_dir) + "/typed.yaml";  // anchors body.dbc
  const ConfigResult r = parse_config(text, config_path);
  ASSERT_TRUE(r.ok()) << listed_errors(r.errors);
  const ChannelSpec& scan = r.config.channels.at(0);
  ASSERT_TRUE(scan.type.has_value());
  EXPECT_EQ(describe(*scan.type),
            "{SpeedFL: float64 [km/h, 0..655.35], SpeedFR: float64 [km/h, 0..655.35], SpeedRL: float64 [km/h, "
            "0..655.35], SpeedRR: float64 [km/h, 0..655.35]}");
  ASSERT_TRUE(scan.type->source.has_value());
  EXPECT_EQ(scan.type->source->name, "WheelSpeeds");
  EXPECT_EQ(scan.type->source->file, std::string(build_paths::dbc_dir) + "/body.dbc");
  EXPECT_NE(std::find(r.included_files.begin(), r.included_files.end(), scan.type->source->file),
            r.included_files.end());
  const std::string written = channel_to_yaml(scan);
  EXPECT_NE(written.find("message: WheelSpeeds"), std::string::npos) << written;
  const ChannelsResult again = parse_channels("[" + written + "]", "bind", r.config);
  ASSERT_TRUE(again.ok()) << listed_errors(again.errors) << written;
  EXPECT_EQ(again.channels.at(0), scan) << written;
}

TEST(ChannelTypeYaml, DbcTypeProblemsAreLocatedInTheYamlOrTheDbcFile) {
  const auto dir = std::filesystem::temp_directory_path() / ("cosmic-dbc-type-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.dbc") << "BO_ 1 A: 8 X\n SG_ _s : 0|8@1+ (1,0) [0|0] \"\" X\n"
                                    "BO_ 2 B: 8 X\n SG_ S : 60|8@1+ (1,0) [0|0] \"\" X\n";
  std::ofstream(dir / "good.dbc") << "BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n";
  const auto errors_for = [&](const std::string& type) {
    return listed_errors(
        parse_config(std::string(kTypedConfigHead) + "    type: " + type + "\n", (dir / "t.yaml").string()).errors);
  };
  const std::string bad = (dir / "bad.dbc").string();
  // The DBC's own error, at its line; no message is taken from a file with errors.
  EXPECT_NE(errors_for("{dbc: bad.dbc, message: A}")
                .find(bad + ":4:2: channels[0].type.dbc: signal 'S' (60|8@1+) "
                            "does not fit the 8 bytes of message 'B'"),
            std::string::npos)
      << errors_for("{dbc: bad.dbc, message: A}");
  const std::string good = (dir / "good.dbc").string();
  EXPECT_NE(errors_for("{dbc: good.dbc, message: Z}")
                .find("t.yaml:12:36: channels[0].type.message: no message 'Z' in " + good),
            std::string::npos)
      << errors_for("{dbc: good.dbc, message: Z}");
  EXPECT_NE(errors_for("{dbc: none.dbc, message: A}").find("channels[0].type.dbc: cannot read DBC file"),
            std::string::npos);
  EXPECT_NE(errors_for("{dbc: good.dbc}").find("channels[0].type: a DBC type names its message"), std::string::npos);
  EXPECT_NE(errors_for("{dbc: good.dbc, message: A, fields: []}").find("channels[0].type.fields"), std::string::npos)
      << errors_for("{dbc: good.dbc, message: A, fields: []}");
  std::ofstream(dir / "underscore.dbc") << "BO_ 1 A: 8 X\n SG_ _s : 0|8@1+ (1,0) [0|0] \"\" X\n";
  EXPECT_NE(errors_for("{dbc: underscore.dbc, message: A}")
                .find((dir / "underscore.dbc").string() +
                      ":2:2: channels[0].type.message: signal name '_s' is not a field name"),
            std::string::npos)
      << errors_for("{dbc: underscore.dbc, message: A}");
  std::filesystem::remove_all(dir);
}

// End-to-end protection on a DBC type (cosmic/e2e_protection.hpp): the counter and CRC are not
// fields, the protection is written back with the source, and what cannot be protected is located
// at the e2e key with the reason.
TEST(ChannelTypeYaml, AnE2eDbcTypeLeavesItsCounterAndCrcOutAndIsWrittenBack) {
  const auto dir = std::filesystem::temp_directory_path() / ("cosmic-e2e-type-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "brake.dbc") << "BO_ 432 Brake: 4 X\n SG_ Crc : 0|8@1+ (1,0) [0|0] \"\" X\n"
                                      " SG_ Counter : 8|4@1+ (1,0) [0|0] \"\" X\n"
                                      " SG_ Pressure : 16|16@1+ (1,0) [0|0] \"bar\" X\n";
  const auto parsed = [&](const std::string& type) {
    return parse_config(std::string(kTypedConfigHead) + "    type: " + type + "\n", (dir / "t.yaml").string());
  };
  const ConfigResult r =
      parsed("{dbc: brake.dbc, message: Brake, e2e: {counter: Counter, crc: Crc, data_id: 0x123, data_id_mode: alt}}");
  ASSERT_TRUE(r.ok()) << listed_errors(r.errors);
  const ChannelSpec& brake = r.config.channels.at(0);
  EXPECT_EQ(describe(*brake.type), "{Pressure: uint16 [bar]}");
  ASSERT_TRUE(brake.type->source->e2e.has_value());
  EXPECT_EQ(*brake.type->source->e2e, (E2eSpec{"Counter", "Crc", 0x123, E2eDataIdMode::alt}));
  EXPECT_EQ(brake.type->source->dbc_message->signals.size(), 3u);  // the frame keeps them
  const std::string written = channel_to_yaml(brake);
  const ChannelsResult again = parse_channels("[" + written + "]", "bind", r.config);
  ASSERT_TRUE(again.ok()) << listed_errors(again.errors) << written;
  EXPECT_EQ(again.channels.at(0), brake) << written;

  const auto errors_for = [&](const std::string& type) { return listed_errors(parsed(type).errors); };
  const std::string wrong =
      errors_for("{dbc: brake.dbc, message: Brake, e2e: {counter: Counter, crc: Pressure, data_id: 1}}");
  EXPECT_NE(wrong.find("t.yaml:12:49: channels[0].type.e2e: the CRC signal Pressure does not fill one whole byte of "
                       "the frame (16 bits at start bit 16); CRC-8 needs one byte of its own"),
            std::string::npos)
      << wrong;
  const std::string missing = errors_for("{dbc: brake.dbc, message: Brake, e2e: {counter: Counter}}");
  EXPECT_NE(missing.find("channels[0].type.e2e: end-to-end protection needs its crc"), std::string::npos) << missing;
  EXPECT_NE(missing.find("channels[0].type.e2e: end-to-end protection needs its data_id"), std::string::npos)
      << missing;
  const std::string range = errors_for(
      "{dbc: brake.dbc, message: Brake, e2e: {counter: Counter, crc: Crc, data_id: 0x10000, data_id_mode: nibble}}");
  EXPECT_NE(range.find("channels[0].type.e2e.data_id: '0x10000' is out of range"), std::string::npos) << range;
  EXPECT_NE(range.find("channels[0].type.e2e.data_id_mode: "), std::string::npos) << range;
  std::filesystem::remove_all(dir);
}

// The signal gateway's native entry (native: {BUS: {dbc, message, map, e2e}}): the identifier is
// the message's, and what does not belong there is refused at its key.
TEST(ChannelTypeYaml, ASignalGatewayEntryTakesItsIdentifierFromTheMessage) {
  const auto dir = std::filesystem::temp_directory_path() / ("cosmic-gw-type-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "a.dbc") << "BO_ 416 A: 2 X\n SG_ S : 0|8@1+ (1,0) [0|200] \"\" X\n";
  std::ofstream(dir / "b.dbc") << "BO_ 768 B: 1 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n";
  const std::string head =
      "gateway: {name: gw, can_node_id: 1}\n"
      "segments:\n"
      "  - {name: body, type: can, interface: can0, bitrate: 500kbit/s}\n"
      "  - {name: chassis, type: can, interface: can1, bitrate: 500kbit/s}\n"
      "channels:\n"
      "  - name: s\n"
      "    subject: 0x10\n"
      "    class: nrt\n"
      "    publishers: [body]\n"
      "    subscribers: [chassis]\n";
  const auto parsed = [&](const std::string& rest) { return parse_config(head + rest, (dir / "t.yaml").string()); };
  const ConfigResult ok = parsed(
      "    type: {dbc: a.dbc, message: A}\n"
      "    native: {body: {can_id: 0x1A0}, chassis: {dbc: b.dbc, message: B}}\n");
  ASSERT_TRUE(ok.ok()) << listed_errors(ok.errors);
  const NativeBinding* chassis = ok.config.channels.at(0).native_on("chassis");
  ASSERT_NE(chassis, nullptr);
  EXPECT_EQ(chassis->can->can_id, 0x300u);
  EXPECT_EQ(ok.config.channels.at(0).payload_on("chassis"), 1u);
  const std::string wrong_id =
      listed_errors(parsed("    type: {dbc: a.dbc, message: A}\n"
                           "    native: {body: {can_id: 0x1A0}, chassis: {dbc: b.dbc, message: B, can_id: 0x301}}\n")
                        .errors);
  EXPECT_NE(wrong_id.find("channels[0].native.chassis.can_id: 0x301 is not message B's identifier 0x300"),
            std::string::npos)
      << wrong_id;
  const std::string untyped = listed_errors(parsed("    native: {chassis: {dbc: b.dbc, message: B}}\n").errors);
  EXPECT_NE(untyped.find("channels[0].native.chassis.dbc: a DBC message on a native hop carries a typed channel's "
                         "fields, and this channel has no type"),
            std::string::npos)
      << untyped;
  const std::string stray =
      listed_errors(parsed("    type: {dbc: a.dbc, message: A}\n"
                           "    native: {body: {can_id: 0x1A0}, chassis: {can_id: 0x300, map: {S: S}}}\n")
                        .errors);
  EXPECT_NE(stray.find("channels[0].native.chassis.map: map belongs to a frame given as a DBC message"),
            std::string::npos)
      << stray;
  // The far message protected end to end: its counter and CRC are the gateway's to write.
  std::ofstream(dir / "c.dbc") << "BO_ 769 C: 3 X\n SG_ Crc : 0|8@1+ (1,0) [0|0] \"\" X\n"
                                  " SG_ Cnt : 8|4@1+ (1,0) [0|0] \"\" X\n SG_ S : 16|8@1+ (1,0) [0|0] \"\" X\n";
  const ConfigResult protected_far = parsed(
      "    type: {dbc: a.dbc, message: A}\n"
      "    native: {body: {can_id: 0x1A0}, chassis: {dbc: c.dbc, message: C, e2e: {counter: Cnt, crc: Crc, data_id: "
      "5}}}\n");
  ASSERT_TRUE(protected_far.ok()) << listed_errors(protected_far.errors);
  const ChannelSpec& channel = protected_far.config.channels.at(0);
  EXPECT_EQ(channel.payload_on("chassis"), 3u);
  const auto form = hop_representation(channel, *protected_far.config.find_segment("chassis"));
  ASSERT_TRUE(form.ok()) << form.error().text;
  EXPECT_EQ(form.value()->describe(), "DBC frame 0x301 C with E2E (counter Cnt, CRC Crc) of c.dbc");
  ASSERT_NE(form.value()->e2e(), nullptr);
  const std::string bad_e2e = listed_errors(parsed("    type: {dbc: a.dbc, message: A}\n"
                                                   "    native: {body: {can_id: 0x1A0}, chassis: {dbc: c.dbc, message: "
                                                   "C, e2e: {counter: S, crc: Cnt, data_id: 5}}}\n")
                                                .errors);
  EXPECT_NE(bad_e2e.find("channels[0].native.chassis.e2e: the CRC signal Cnt does not fill one whole byte"),
            std::string::npos)
      << bad_e2e;
  std::filesystem::remove_all(dir);
}

// ROS 2 types (issue 35): a .msg message and an IDL struct as rosidl lays them out, their
// dependencies found under the root FILE lies in (ROOT/pkg/msg/Name.*) or on type_path; an error in
// a dependency is located in that file; the source is written back with the resolved type_path.
TEST(ChannelTypeYaml, RosMessagesAndIdlStructsGiveTheFieldsWithTheirDependencies) {
  const auto dir = std::filesystem::temp_directory_path() / ("cosmic-ros-type-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "ros" / "geometry_msgs" / "msg");
  std::filesystem::create_directories(dir / "extra" / "geometry_msgs" / "msg");
  std::ofstream(dir / "ros" / "geometry_msgs" / "msg" / "Twist.msg")
      << "# This expresses velocity in free space.\nVector3  linear\nVector3  angular\n";
  std::ofstream(dir / "extra" / "geometry_msgs" / "msg" / "Vector3.msg") << "float64 x\nfloat64 y\nfloat64 z\n";
  std::ofstream(dir / "ros" / "geometry_msgs" / "msg" / "Twist.idl")
      << "#include \"geometry_msgs/msg/Vector3.idl\"\nmodule geometry_msgs { module msg {\n"
         "  struct Twist { geometry_msgs::msg::Vector3 linear; geometry_msgs::msg::Vector3 angular; };\n}; };\n";
  std::ofstream(dir / "ros" / "geometry_msgs" / "msg" / "Vector3.idl")
      << "module geometry_msgs { module msg {\n  struct Vector3 { double x; double y; double z; };\n}; };\n";
  const auto load = [&](const std::string& type) {
    std::ofstream(dir / "t.yaml") << std::string(kTypedConfigHead) + "    type: " + type + "\n";
    return parse_config(std::string(kTypedConfigHead) + "    type: " + type + "\n", (dir / "t.yaml").string());
  };
  const std::string twist =
      "{linear: {x: float64, y: float64, z: float64}, angular: {x: float64, y: float64, z: float64}}";
  const ConfigResult msg =
      load("{msg: ros/geometry_msgs/msg/Twist.msg, name: geometry_msgs/msg/Twist, type_path: [extra]}");
  ASSERT_TRUE(msg.ok()) << listed_errors(msg.errors);
  EXPECT_EQ(describe(*msg.config.channels[0].type), twist);
  EXPECT_EQ(msg.config.channels[0].type->source->type_path, std::vector<std::string>{(dir / "extra").string()});
  const ConfigResult idl = load("{idl: ros/geometry_msgs/msg/Twist.idl, name: \"geometry_msgs::msg::Twist\"}");
  ASSERT_TRUE(idl.ok()) << listed_errors(idl.errors);
  EXPECT_EQ(describe(*idl.config.channels[0].type), twist);
  // Without type_path, Vector3.msg is nowhere: the error names it.
  const ConfigResult missing = load("{msg: ros/geometry_msgs/msg/Twist.msg, name: geometry_msgs/msg/Twist}");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(listed_errors(missing.errors).find("Vector3"), std::string::npos) << listed_errors(missing.errors);
  // An error in an included IDL file is located in it.
  std::ofstream(dir / "ros" / "geometry_msgs" / "msg" / "Vector3.idl")
      << "module geometry_msgs { module msg {\n  struct Vector3 { double x; wchar y; };\n}; };\n";
  const ConfigResult bad = load("{idl: ros/geometry_msgs/msg/Twist.idl, name: \"geometry_msgs::msg::Twist\"}");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(listed_errors(bad.errors).find("geometry_msgs/msg/Vector3.idl:2:"), std::string::npos)
      << listed_errors(bad.errors);
  std::filesystem::remove_all(dir);
}

TEST(ChannelTypeYaml, AnLcmStructGivesTheFieldsAndIsWrittenBackWithItsBounds) {
  const auto dir = std::filesystem::temp_directory_path() / ("cosmic-lcm-type-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "scan.lcm") << "package sensors;\nstruct scan_t {\n  int64_t utime;\n  int32_t n;\n"
                                     "  float ranges[n];\n  string frame;\n}\n";
  const auto load = [&](const std::string& type) {
    return parse_config(std::string(kTypedConfigHead) + "    type: " + type + "\n", (dir / "t.yaml").string());
  };
  const ConfigResult r = load("{lcm: scan.lcm, name: sensors.scan_t, max_length: {ranges: 1081}}");
  ASSERT_TRUE(r.ok()) << listed_errors(r.errors);
  const ChannelSpec& scan = r.config.channels.at(0);
  ASSERT_TRUE(scan.type.has_value());
  EXPECT_EQ(describe(*scan.type), "{utime: int64, n: int32, ranges: sequence<float32, 1081>, frame: string<=65536>}");
  ASSERT_TRUE(scan.type->source.has_value());
  EXPECT_EQ(scan.type->source->format, TypeSource::Format::lcm);
  EXPECT_EQ(scan.type->source->name, "sensors.scan_t");
  const std::string written = channel_to_yaml(scan);
  const ChannelsResult again = parse_channels("[" + written + "]", "bind", r.config);
  ASSERT_TRUE(again.ok()) << listed_errors(again.errors) << written;
  EXPECT_EQ(again.channels.at(0), scan) << written;

  const std::string lcm = (dir / "scan.lcm").string();
  EXPECT_NE(listed_errors(load("{lcm: scan.lcm, name: scan_t}").errors)
                .find("t.yaml:12:33: channels[0].type.name: no struct 'scan_t' in " + lcm),
            std::string::npos)
      << listed_errors(load("{lcm: scan.lcm, name: scan_t}").errors);
  EXPECT_NE(
      listed_errors(load("{lcm: scan.lcm, name: sensors.scan_t, max_length: {frame: 4}}").errors)
          .find(lcm +
                ":2:1: channels[0].type.name: max_length names frame, which is not a variable-length array member"),
      std::string::npos)
      << listed_errors(load("{lcm: scan.lcm, name: sensors.scan_t, max_length: {frame: 4}}").errors);
  EXPECT_NE(listed_errors(load("{lcm: scan.lcm, name: sensors.scan_t, max_length: {ranges: 0}}").errors)
                .find("channels[0].type.max_length.ranges"),
            std::string::npos);
  std::ofstream(dir / "broken.lcm") << "struct t { int16_t b[n]; }\n";
  EXPECT_NE(
      listed_errors(load("{lcm: broken.lcm, name: t}").errors)
          .find((dir / "broken.lcm").string() + ":1:20: channels[0].type.lcm: the size of b, 'n', is not an integer"),
      std::string::npos)
      << listed_errors(load("{lcm: broken.lcm, name: t}").errors);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cosmic
