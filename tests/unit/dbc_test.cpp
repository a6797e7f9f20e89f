// The DBC reader (cosmic/dbc.hpp): messages, their identifiers, lengths and GenMsgCycleTime from
// real-looking files; every statement of the format walked without error; every error located
// at its line and column; the limits that keep hostile input cheap.
#include "cosmic/build_paths.hpp"
#include "cosmic/dbc.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cosmic {
namespace {

// One line per message: "name id std|ext length cycle line:column".
std::string summary(const DbcMessage& m) {
  std::ostringstream out;
  out << m.name << " 0x" << std::hex << std::uppercase << m.can_id << std::dec << (m.extended ? " ext " : " std ")
      << m.length << " ";
  if (m.cycle_time) {
    out << std::chrono::duration_cast<std::chrono::milliseconds>(*m.cycle_time).count() << "ms";
  } else {
    out << "event";
  }
  out << " " << m.line << ":" << m.column;
  return out.str();
}

std::vector<std::string> messages_of(const DbcFile& file) {
  std::vector<std::string> out;
  for (const DbcMessage& m : file.messages) out.push_back(summary(m));
  return out;
}

// "line:column: message" per error.
std::vector<std::string> errors_of(const DbcFile& file) {
  std::vector<std::string> out;
  for (const DbcError& e : file.errors)
    out.push_back(std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  return out;
}

std::vector<std::string> errors_of(std::string_view text) { return errors_of(parse_dbc(text)); }

std::string read_sample(const std::string& name) {
  std::ifstream in(std::string(cosmic::build_paths::dbc_dir) + "/" + name, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string with_crlf(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

// Every statement kind of the format, multiplexed signals, comments holding quotes, ';' and
// things that look like statements.
constexpr std::string_view kRealistic = R"(VERSION "3.1"

NS_ :
	NS_DESC_
	CM_
	BA_DEF_
	BA_
	VAL_
	BA_DEF_DEF_
	SIG_VALTYPE_
	SG_MUL_VAL_

BS_:

BU_: Ecu Tool

VAL_TABLE_ OnOff 1 "On" 0 "Off" ;

BO_ 100 Speed: 8 Ecu
 SG_ Value : 0|16@1+ (0.01,0) [0|655.35] "km/h" Tool

BO_ 2566844672 Diag: 8 Tool
 SG_ Mode M : 0|8@1+ (1,0) [0|255] "" Ecu
 SG_ Dtc m0 : 8|16@1+ (1,0) [0|0] "" Ecu
 SG_ Freeze m1 : 8|32@1- (1,0) [0|0] "" Ecu
 SG_ Sub m2M : 8|8@1+ (1,0) [0|0] "" Ecu
 SG_ Deep m7 : 16|8@1+ (1,0) [0|0] "" Ecu

   BO_ 2047 Status: 1 Ecu

CM_ "A comment with a \"quote\"; a semicolon
BO_ 5 Fake: 8 Ecu
and a line that looks like a message.";
CM_ BO_ 100 "multi
line; with ; inside";
CM_ SG_ 2566844672 Mode "Selects \"Dtc\" or \"Freeze\"";
CM_ BU_ Tool "a 19\" rack; BO_ 6 Fake: 8 Ecu";
BA_DEF_ BO_  "GenMsgCycleTime" INT 0 65535;
BA_DEF_ BO_  "GenMsgSendType" ENUM  "Cyclic","NotUsed",
  "IfActive";
BA_DEF_  "DBName" STRING ;
BA_DEF_ SG_  "GenSigStartValue" FLOAT -1e3 1E+3;
BA_DEF_DEF_  "GenMsgCycleTime" 50;
BA_DEF_DEF_  "GenMsgSendType" "Cyclic";
BA_DEF_DEF_  "DBName" "";
BA_ "DBName" "Powertrain";
BA_ "GenMsgCycleTime" BO_ 100 10;
BA_ "GenMsgSendType" BO_ 2047 2;
BA_ "GenMsgCycleTime" BO_ 2047 0;
BA_ "GenSigStartValue" SG_ 100 Value 2.5;
VAL_ 2566844672 Mode 1 "Freeze" 0 "Dtc" ;
SIG_VALTYPE_ 2566844672 Freeze : 1;
SG_MUL_VAL_ 2566844672 Deep Sub 7-7;
)";

const std::vector<std::string> kRealisticMessages{"Speed 0x64 std 8 10ms 19:1", "Diag 0x18FEF100 ext 8 50ms 22:1",
                                                  "Status 0x7FF std 1 event 29:4"};

TEST(DbcParse, RealisticFileGivesEveryMessage) {
  const DbcFile file = parse_dbc(kRealistic);
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), kRealisticMessages);
}

TEST(DbcParse, CrlfLineEndingsAndBomChangeNothing) {
  const DbcFile file = parse_dbc("\xEF\xBB\xBF" + with_crlf(kRealistic));
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), kRealisticMessages);
  EXPECT_EQ(messages_of(parse_dbc("\xEF\xBB\xBF BO_ 1 A: 8 X\r\n")), std::vector<std::string>{"A 0x1 std 8 event 1:2"});
  // Errors, too, are located as without the BOM and the carriage returns.
  EXPECT_EQ(errors_of("\xEF\xBB\xBF" + with_crlf("VERSION \"\"\r\nBO_ 1 A 8 X\n")),
            std::vector<std::string>{"2:9: expected ':' after the message name, found '8'"});
}

TEST(DbcParse, IndependentSignalsPseudoMessageIsSkipped) {
  const DbcFile file = parse_dbc(R"(BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX
 SG_ Orphan : 0|8@1+ (1,0) [0|0] "" Vector__XXX
BO_ 1 Real: 8 X
CM_ SG_ 3221225472 Orphan "kept for later";
BA_ "GenMsgCycleTime" BO_ 3221225472 10;
)");
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), std::vector<std::string>{"Real 0x1 std 8 event 3:1"});
}

TEST(DbcParse, UnknownAndUnusedStatementsAreSkippedSilently) {
  const DbcFile file = parse_dbc(R"(VERSION ""
NS_ :
CM_
BA_DEF_
BS_: 500 : 12,34
BU_: A B
EV_ Switch: 0 [0|3] "" 0 1 DUMMY_NODE_VECTOR0 Vector__XXX;
ENVVAR_DATA_ Switch: 4;
SGTYPE_ Temp : 8@1+ (1,-40) [-40|215] "degC" 0 , Tbl;
FUTURE_THING_ 1 2 "three" (4) [5|6]
BO_ 300 M1: 64 A
 SG_ S : 0|8@1+ (1,0) [0|0] "" B
BO_TX_BU_ 300 : A,B;
SIG_GROUP_ 300 Grp 1 : S;
BA_DEF_REL_ BU_SG_REL_ "GenSigTimeoutTime" INT 0 65535;
BA_DEF_DEF_REL_ "GenSigTimeoutTime" 0;
BA_REL_ "GenSigTimeoutTime" BU_SG_REL_ B SG_ 300 S 100;
CAT_DEF_ 1 Cat 0; FILTER 0 1;
VAL_ 300 S 1 "one" 0 "zero" ;
)");
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), std::vector<std::string>{"M1 0x12C std 64 event 11:1"});
}

TEST(DbcParse, NewSymbolsMayStandUnindentedAndTheListEndsAtTheFirstStatement) {
  // A name alone on its line is a new symbol, even a keyword at column 1; a line of more tokens is a statement.
  const DbcFile file =
      parse_dbc("NS_ : NS_DESC_\nCM_\nBA_\n BO_\nBO_TX_BU_\nVAL_TABLE_ T 1 \"a\" ;\nBO_ 7 Seven: 8 X\n");
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), std::vector<std::string>{"Seven 0x7 std 8 event 7:1"});
}

TEST(DbcParse, StatementsMayShareALine) {
  const DbcFile file = parse_dbc("BA_DEF_DEF_ \"GenMsgCycleTime\" 20; BO_ 8 Eight: 2 X\nBO_ 9 Nine: 3 X\n");
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), (std::vector<std::string>{"Eight 0x8 std 2 20ms 1:35", "Nine 0x9 std 3 20ms 2:1"}));
}

TEST(DbcParse, EveryCanFdLengthIsAccepted) {
  std::string text;
  for (const int length : {0, 1, 8, 12, 16, 20, 24, 32, 48, 64}) {
    text +=
        "BO_ " + std::to_string(100 + length) + " L" + std::to_string(length) + ": " + std::to_string(length) + " X\n";
  }
  const DbcFile file = parse_dbc(text);
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  ASSERT_EQ(file.messages.size(), 10u);
  EXPECT_EQ(file.messages[3].length, 12u);
  EXPECT_EQ(file.messages[9].length, 64u);
}

TEST(DbcParse, EmptyTextHasNoMessagesAndNoErrors) {
  EXPECT_TRUE(parse_dbc("").ok());
  EXPECT_TRUE(parse_dbc("\xEF\xBB\xBF \r\n\t\n").ok());
  EXPECT_TRUE(parse_dbc("").messages.empty());
}

// ---------------------------------------------------------------- GenMsgCycleTime

TEST(DbcCycleTime, ExplicitValueWinsOverDefaultAndZeroMeansNone) {
  const DbcFile file = parse_dbc(R"(BO_ 1 A: 8 X
BO_ 2 B: 8 X
BO_ 3 C: 8 X
BA_DEF_DEF_ "GenMsgCycleTime" 100;
BA_ "GenMsgCycleTime" BO_ 1 10;
BA_ "GenMsgCycleTime" BO_ 3 0;
)");
  EXPECT_TRUE(file.ok());
  EXPECT_EQ(messages_of(file),
            (std::vector<std::string>{"A 0x1 std 8 10ms 1:1", "B 0x2 std 8 100ms 2:1", "C 0x3 std 8 event 3:1"}));
  EXPECT_EQ(file.messages[0].cycle_time, Nanos(10'000'000));
}

TEST(DbcCycleTime, WithoutDefaultOrWithDefaultZeroOnlyExplicitValuesCount) {
  constexpr std::string_view kMessages = "BO_ 1 A: 8 X\nBO_ 2 B: 8 X\nBA_ \"GenMsgCycleTime\" BO_ 2 20;\n";
  EXPECT_EQ(messages_of(parse_dbc(kMessages)),
            (std::vector<std::string>{"A 0x1 std 8 event 1:1", "B 0x2 std 8 20ms 2:1"}));
  const std::string zero_default = std::string(kMessages) + "BA_DEF_DEF_ \"GenMsgCycleTime\" 0;\n";
  EXPECT_EQ(messages_of(parse_dbc(zero_default)),
            (std::vector<std::string>{"A 0x1 std 8 event 1:1", "B 0x2 std 8 20ms 2:1"}));
}

TEST(DbcCycleTime, ExtendedIdsAreNamedWithBit31AndTheLastValueWins) {
  const DbcFile file = parse_dbc(R"(BA_ "GenMsgCycleTime" BO_ 2147483905 5;
BO_ 2147483905 Ext: 8 X
BO_ 257 Std: 8 X
BA_ "GenMsgCycleTime" BO_ 2147483905 7;
BA_ "GenMsgCycleTime" BO_ 257 1000;
)");
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), (std::vector<std::string>{"Ext 0x101 ext 8 7ms 2:1", "Std 0x101 std 8 1000ms 3:1"}));
}

TEST(DbcCycleTime, OtherAttributesDoNotCount) {
  const DbcFile file = parse_dbc(R"(BO_ 1 A: 8 X
BA_DEF_ BO_ "GenMsgCycleTimeFast" INT 0 100;
BA_DEF_ BO_ "GenMsgSendType" ENUM "Cyclic","Event";
BA_DEF_DEF_ "GenMsgCycleTimeFast" 10;
BA_ "GenMsgCycleTimeFast" BO_ 1 10;
BA_ "GenMsgSendType" BO_ 1 1;
BA_ "GenMsgDelayTime" BO_ 1 -3;
BA_ "Comment" BO_ 1 "GenMsgCycleTime";
)");
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), std::vector<std::string>{"A 0x1 std 8 event 1:1"});
}

// ---------------------------------------------------------------- errors, each located

TEST(DbcErrors, MessageLineSyntax) {
  EXPECT_EQ(errors_of("BO_ abc Foo: 8 X\n"),
            std::vector<std::string>{"1:5: expected the message id (a decimal number) after BO_, found 'abc'"});
  EXPECT_EQ(errors_of("BO_\nBO_ 1 A: 8 X\n"),
            std::vector<std::string>{"1:4: expected the message id (a decimal number) after BO_"});
  EXPECT_EQ(errors_of("BO_ 100 : 8 X\n"),
            std::vector<std::string>{"1:9: expected the message name after the id, found ':'"});
  EXPECT_EQ(errors_of("BO_ 100 Foo 8 X\n"),
            std::vector<std::string>{"1:13: expected ':' after the message name, found '8'"});
  EXPECT_EQ(errors_of("BO_ 100 Foo: X\n"),
            std::vector<std::string>{"1:14: expected the message length in bytes after ':', found 'X'"});
  EXPECT_EQ(errors_of("BO_ 100 Foo: 8\n SG_ A : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"1:15: expected the transmitting node after the length"});
  EXPECT_EQ(errors_of("BO_ 100 Foo: 8 X Y\n"),
            std::vector<std::string>{"1:18: unexpected 'Y' after the transmitting node"});
}

TEST(DbcErrors, MessageIdOutOfRange) {
  EXPECT_EQ(errors_of("BO_ 4294967296 Foo: 8 X\n"),
            std::vector<std::string>{"1:5: message id '4294967296' is not a decimal number from 0 to 4294967295"});
  EXPECT_EQ(errors_of("BO_ 0x100 Foo: 8 X\n"),
            std::vector<std::string>{"1:5: message id '0x100' is not a decimal number from 0 to 4294967295"});
  EXPECT_EQ(errors_of("BO_ -1 Foo: 8 X\n"),
            std::vector<std::string>{"1:5: message id '-1' is not a decimal number from 0 to 4294967295"});
  EXPECT_EQ(
      errors_of("\n  BO_ 2048 Foo: 8 X\n"),
      std::vector<std::string>{
          "2:7: standard message id 2048 (0x800) is above 0x7FF (an extended id has bit 31 set: add 2147483648)"});
  // 0xA0000000: bit 31 and bit 29.
  EXPECT_EQ(
      errors_of("BO_ 2684354560 Foo: 8 X\n"),
      std::vector<std::string>{
          "1:5: extended message id 2684354560 does not fit 29 bits: 0x20000000 > 0x1FFFFFFF after removing bit 31"});
  // The largest of each kind are fine.
  EXPECT_TRUE(parse_dbc("BO_ 2047 A: 8 X\nBO_ 2684354559 B: 8 X\n").ok());
}

TEST(DbcErrors, MessageLengthOutOfRange) {
  EXPECT_EQ(errors_of("BO_ 1 A: 65 X\n"),
            std::vector<std::string>{"1:10: message length 65 is out of range (0..64 bytes)"});
  EXPECT_EQ(
      errors_of("BO_ 1 A: 10 X\n"),
      std::vector<std::string>{"1:10: message length 10 is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48 or 64)"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8.5 X\n"),
            std::vector<std::string>{"1:10: message length '8.5' is not a whole number of bytes (0..64)"});
  EXPECT_EQ(errors_of("BO_ 1 A: -8 X\n"),
            std::vector<std::string>{"1:10: message length '-8' is not a whole number of bytes (0..64)"});
  EXPECT_TRUE(parse_dbc("BO_ 1 A: 65 X\n").messages.empty());
}

TEST(DbcErrors, DuplicateIdsAndNamesNameBothLines) {
  const DbcFile file = parse_dbc("BO_ 16 A: 8 X\nBO_ 17 B: 8 X\nBO_ 16 C: 8 X\nBO_ 18 B: 8 X\nBO_ 16 D: 8 X\n");
  EXPECT_EQ(errors_of(file), (std::vector<std::string>{
                                 "3:5: duplicate message id 16 (0x10): 'C' repeats the id of 'A' declared at line 1",
                                 "4:8: duplicate message name 'B': already declared at line 2",
                                 "5:5: duplicate message id 16 (0x10): 'D' repeats the id of 'A' declared at line 1",
                             }));
  // The first of each is kept.
  EXPECT_EQ(messages_of(file), (std::vector<std::string>{"A 0x10 std 8 event 1:1", "B 0x11 std 8 event 2:1"}));
  // A standard and an extended frame with the same number are different frames.
  EXPECT_TRUE(parse_dbc("BO_ 16 A: 8 X\nBO_ 2147483664 B: 8 X\n").ok());
  EXPECT_EQ(errors_of("BO_ 2147483664 A: 8 X\nBO_ 2147483664 B: 8 X\n"),
            std::vector<std::string>{
                "2:5: duplicate message id 2147483664 (extended 0x10): 'B' repeats the id of 'A' declared at line 1"});
}

TEST(DbcErrors, CycleTimeForAnUndeclaredMessage) {
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\nBA_ \"GenMsgCycleTime\" BO_ 2 10;\n"),
            std::vector<std::string>{"2:27: BA_ \"GenMsgCycleTime\" names message id 2 (0x2), which no BO_ declares"});
  // A message that is declared but refused (here its length) does not cause a second error.
  EXPECT_EQ(
      errors_of("BO_ 1 A: 9 X\nBA_ \"GenMsgCycleTime\" BO_ 1 10;\n"),
      std::vector<std::string>{"1:10: message length 9 is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48 or 64)"});
}

TEST(DbcErrors, CycleTimeValues) {
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\nBA_ \"GenMsgCycleTime\" BO_ 1 -10;\n"),
            std::vector<std::string>{"2:29: GenMsgCycleTime must not be negative, found '-10'"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\nBA_ \"GenMsgCycleTime\" BO_ 1 12.5;\n"),
            std::vector<std::string>{
                "2:29: GenMsgCycleTime must be a whole number of milliseconds (0..4294967295), found '12.5'"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\nBA_ \"GenMsgCycleTime\" BO_ 1 \"10\";\n"),
            std::vector<std::string>{"2:29: expected GenMsgCycleTime in whole milliseconds, found the string '10'"});
  EXPECT_EQ(errors_of("BA_DEF_DEF_ \"GenMsgCycleTime\" -1;\n"),
            std::vector<std::string>{"1:31: GenMsgCycleTime must not be negative, found '-1'"});
  EXPECT_EQ(errors_of("BA_DEF_DEF_ \"GenMsgCycleTime\" 1e2;\n"),
            std::vector<std::string>{
                "1:31: GenMsgCycleTime must be a whole number of milliseconds (0..4294967295), found '1e2'"});
  EXPECT_EQ(errors_of("BA_DEF_DEF_ \"GenMsgCycleTime\" 4294967296;\n"),
            std::vector<std::string>{
                "1:31: GenMsgCycleTime must be a whole number of milliseconds (0..4294967295), found '4294967296'"});
  // The largest value is kept exactly.
  const DbcFile longest = parse_dbc("BO_ 1 A: 8 X\nBA_ \"GenMsgCycleTime\" BO_ 1 4294967295;\n");
  ASSERT_EQ(longest.messages.size(), 1u);
  EXPECT_EQ(longest.messages[0].cycle_time, Nanos(4'294'967'295LL * 1'000'000));
}

TEST(DbcErrors, AttributeStatementSyntax) {
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\nBA_ \"GenMsgCycleTime\" BO_ 1 10\nBO_ 2 B: 8 X\n"),
            std::vector<std::string>{"2:31: expected ';' after the attribute value"});
  EXPECT_EQ(errors_of("BA_DEF_DEF_ \"GenMsgCycleTime\" 10 11;\n"),
            std::vector<std::string>{"1:34: expected ';' after the default value, found '11'"});
  EXPECT_EQ(errors_of("BA_ \"GenMsgCycleTime\" SG_ 1 S 10;\n"),
            std::vector<std::string>{
                "1:23: expected BO_ and a message id after \"GenMsgCycleTime\" (a message attribute), found 'SG_'"});
  EXPECT_EQ(errors_of("BA_ \"GenMsgCycleTime\" BO_ A 10;\n"),
            std::vector<std::string>{"1:27: expected the message id after BO_, found 'A'"});
  EXPECT_EQ(errors_of("BA_ GenMsgCycleTime BO_ 1 10;\n"),
            std::vector<std::string>{
                "1:5: expected the attribute name as a quoted string after BA_, found 'GenMsgCycleTime'"});
  EXPECT_EQ(
      errors_of("BA_DEF_DEF_ 10;\n"),
      std::vector<std::string>{"1:13: expected the attribute name as a quoted string after BA_DEF_DEF_, found '10'"});
  EXPECT_EQ(
      errors_of("BA_DEF_ XX_ \"A\" INT 0 1;\n"),
      std::vector<std::string>{
          "1:9: expected BU_, BO_, SG_, EV_ or the attribute name as a quoted string after BA_DEF_, found 'XX_'"});
  EXPECT_EQ(errors_of("BA_DEF_ BO_ INT 0 1;\n"),
            std::vector<std::string>{"1:13: expected the attribute name as a quoted string, found 'INT'"});
}

TEST(DbcErrors, SignalLineSyntax) {
  EXPECT_EQ(errors_of("VERSION \"\"\n SG_ A : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:2: SG_ outside a message: a signal line must follow its BO_ line"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\n SG_ : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:6: expected the signal name after SG_, found ':'"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\n SG_ S 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:8: expected ':' after the signal name, found '0'"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\n SG_ S x3 : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{
                "2:8: expected ':' or a multiplexer indicator (M, m<n> or m<n>M) after the signal name, found 'x3'"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\n SG_ S mM : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{
                "2:8: expected ':' or a multiplexer indicator (M, m<n> or m<n>M) after the signal name, found 'mM'"});
  EXPECT_EQ(errors_of("BO_ 1 A: 8 X\n SG_ S m1 0|8@1+ (1,0) [0|0] \"\" X\n"),
            std::vector<std::string>{"2:11: expected ':' after the multiplexer indicator, found '0'"});
}

TEST(DbcErrors, UnterminatedStringStopsAtItsStartAndKeepsWhatCameBefore) {
  const DbcFile file = parse_dbc("BO_ 1 A: 8 X\nCM_ BO_ 1 \"never\nclosed \\\";\nBO_ 2 B: 8 X\n");
  EXPECT_EQ(errors_of(file),
            std::vector<std::string>{"2:11: unterminated string: no closing '\"' before the end of the text"});
  EXPECT_EQ(messages_of(file), std::vector<std::string>{"A 0x1 std 8 event 1:1"});
  // Inside a statement that is being checked, the cut-off statement adds no error of its own.
  EXPECT_EQ(errors_of("BA_ \"GenMsgCycleTime\" BO_ 1 \"10;\n"),
            std::vector<std::string>{"1:29: unterminated string: no closing '\"' before the end of the text"});
}

TEST(DbcErrors, AllErrorsAreReportedInTextOrder) {
  EXPECT_EQ(errors_of("BA_ \"GenMsgCycleTime\" BO_ 9 10;\nBO_ 1 A 8 X\nBO_ 2 B: 99 X\nBO_ 3 C: 8 X\n"),
            (std::vector<std::string>{
                "1:27: BA_ \"GenMsgCycleTime\" names message id 9 (0x9), which no BO_ declares",
                "2:9: expected ':' after the message name, found '8'",
                "3:10: message length 99 is out of range (0..64 bytes)",
            }));
}

// ---------------------------------------------------------------- limits

TEST(DbcLimits, TextAbove8MiBIsOneErrorAndUnread) {
  const std::string too_long(kDbcMaxTextBytes + 1, ' ');
  EXPECT_EQ(errors_of(too_long),
            std::vector<std::string>{"0:0: the DBC text has 8388609 bytes, more than the limit of 8388608 (8 MiB)"});
  std::string largest = "BO_ 1 A: 8 X\n";
  largest.resize(kDbcMaxTextBytes, '\n');
  const DbcFile file = parse_dbc(largest);
  EXPECT_TRUE(file.ok());
  EXPECT_EQ(file.messages.size(), 1u);
}

TEST(DbcLimits, MoreThan20000MessagesIsAnError) {
  // Extended ids, so that each of them is unique.
  std::string text;
  for (std::size_t i = 0; i <= kDbcMaxMessages; ++i) {
    text += "BO_ " + std::to_string(0x8000'0000u + i) + " M" + std::to_string(i) + ": 8 X\n";
  }
  const DbcFile file = parse_dbc(text);
  EXPECT_EQ(errors_of(file), std::vector<std::string>{"20001:1: more than 20000 messages (the limit of one DBC file)"});
  EXPECT_EQ(file.messages.size(), kDbcMaxMessages);
}

TEST(DbcLimits, ErrorsAreCappedWithAClosingCount) {
  std::string text;
  for (int i = 0; i < 150; ++i) text += "BO_ x\n";
  const DbcFile file = parse_dbc(text);
  ASSERT_EQ(file.errors.size(), kDbcMaxReportedErrors + 1);
  EXPECT_EQ(errors_of(file)[0], "1:5: expected the message id (a decimal number) after BO_, found 'x'");
  EXPECT_EQ(errors_of(file)[99], "100:5: expected the message id (a decimal number) after BO_, found 'x'");
  EXPECT_EQ(errors_of(file)[100], "0:0: 50 more errors not reported (only the first 100 are)");
  EXPECT_FALSE(file.ok());
}

TEST(DbcLimits, HostileLongTokensAreQuotedShort) {
  const std::string name(100'000, 'N');
  const std::string cut = "'" + std::string(24, 'N') + "...' (100000 characters)";
  EXPECT_EQ(errors_of("BO_ 1 A " + name + " 8 X\n"),
            std::vector<std::string>{"1:9: expected ':' after the message name, found " + cut});
  EXPECT_EQ(errors_of("BO_ 1 " + name + ": 8 X\nBO_ 2 " + name + ": 8 X\n"),
            std::vector<std::string>{"2:7: duplicate message name " + cut + ": already declared at line 1"});
}

// ---------------------------------------------------------------- sample files

TEST(DbcFiles, BodyBus) {
  const DbcFile file = parse_dbc(read_sample("body.dbc"));
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), (std::vector<std::string>{
                                   "BodyStatus 0x100 std 8 100ms 42:1",
                                   "DoorEvent 0x120 std 2 event 48:1",
                                   "WheelSpeeds 0x1A0 std 8 10ms 52:1",
                                   "LightControl 0x200 std 4 20ms 58:1",
                                   "SeatControl 0x400 std 6 20ms 64:1",
                                   "BodyDiag 0x18DAF110 ext 8 100ms 72:1",
                                   "ChargePortStatus 0xCF00400 ext 8 10ms 76:1",
                               }));
}

TEST(DbcFiles, PowertrainOnCanFd) {
  const DbcFile file = parse_dbc(read_sample("powertrain_fd.dbc"));
  EXPECT_TRUE(file.ok()) << ::testing::PrintToString(errors_of(file));
  EXPECT_EQ(messages_of(file), (std::vector<std::string>{
                                   "EngineData 0x64 std 16 10ms 31:1",
                                   "InverterState 0x65 std 64 100ms 37:1",
                                   "VcuCommand 0x66 std 12 5ms 45:1",
                                   "VcuDiagnostics 0xC000003 ext 48 100ms 49:1",
                                   "VcuWake 0x67 std 0 event 52:1",
                               }));
}

}  // namespace
}  // namespace cosmic
