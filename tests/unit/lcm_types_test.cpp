// LCM type files (cosmic/lcm_types.hpp): structs, members, dimensions and constants read as
// lcm-gen reads them, every problem located, fingerprints equal to the ones lcm-gen generated for
// the same text (lcm-gen 1.4 -p; tests/integration/lcm_types checks more against lcm-gen itself),
// and the types typed channels get.
#include "cosmic/lcm_types.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace cosmic {
namespace {

constexpr std::string_view kExample = R"lcm(package exlcm;
/* a nested struct first */
struct inner_t { int32_t a; double b[2]; }
struct example_t
{
    int64_t  timestamp;   // ns
    double   position[3];
    int32_t  num_ranges;
    int16_t  ranges[num_ranges];
    string   name;
    boolean  enabled;
    byte     grid[2][num_ranges];
    const int32_t YELLOW=1, GOLDENROD=2;
    inner_t  nested;
    float    f;
    int8_t   s8;
}
)lcm";

std::vector<std::string> lcm_errors(std::string_view text) {
  std::vector<std::string> out;
  for (const LcmError& e : parse_lcm_types(text).errors)
    out.push_back(std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  return out;
}

TEST(LcmTypes, StructsMembersDimensionsAndConstants) {
  const LcmTypeFile file = parse_lcm_types(kExample);
  ASSERT_TRUE(file.ok()) << file.errors.front().message;
  ASSERT_EQ(file.structs.size(), 2u);
  const LcmStruct* example = file.find("exlcm.example_t");
  ASSERT_NE(example, nullptr);
  EXPECT_EQ(example->members.size(), 10u);
  EXPECT_EQ(example->members[3].name, "ranges");
  ASSERT_EQ(example->members[3].dimensions.size(), 1u);
  EXPECT_TRUE(example->members[3].dimensions[0].variable);
  EXPECT_EQ(example->members[6].dimensions[0].size, "2");
  EXPECT_EQ(example->members[7].type, "exlcm.inner_t");
  ASSERT_EQ(example->constants.size(), 2u);
  EXPECT_EQ(example->constants[1].name, "GOLDENROD");
}

TEST(LcmTypes, FingerprintsAreLcmGens) {
  const LcmTypeFile file = parse_lcm_types(kExample);
  ASSERT_TRUE(file.ok());
  // The constants lcm-gen 1.4.0 wrote into exlcm/inner_t.py and exlcm/example_t.py for this text.
  EXPECT_EQ(static_cast<std::uint64_t>(lcm_base_hash(*file.find("exlcm.inner_t"))), 0x39ce88f20f994688u);
  EXPECT_EQ(static_cast<std::uint64_t>(lcm_base_hash(*file.find("exlcm.example_t"))), 0x126525ed76953ae5u);
  const auto rotate = [](std::uint64_t v) { return (v << 1) | (v >> 63); };
  const std::uint64_t inner = rotate(0x39ce88f20f994688u);
  EXPECT_EQ(lcm_fingerprint(file, *file.find("exlcm.inner_t")), inner);
  EXPECT_EQ(lcm_fingerprint(file, *file.find("exlcm.example_t")), rotate(0x126525ed76953ae5u + inner));
}

TEST(LcmTypes, TheTypeATypedChannelGets) {
  const LcmTypeFile file = parse_lcm_types(kExample);
  const LcmChannelType typed = lcm_channel_type(file, *file.find("exlcm.example_t"), {{"ranges", 1081}, {"grid", 100}});
  ASSERT_TRUE(typed.ok()) << typed.errors.front().message;
  EXPECT_EQ(describe(typed.type),
            "{timestamp: int64, position: float64[3], num_ranges: int32, ranges: sequence<int16, 1081>, name: "
            "string<=65536>, enabled: bool, grid: sequence<uint8, 100>[2], nested: {a: int32, b: float64[2]}, f: "
            "float32, s8: int8}");
  const LcmChannelType wrong = lcm_channel_type(file, *file.find("exlcm.example_t"), {{"name", 3}, {"ranges", 0}});
  ASSERT_EQ(wrong.errors.size(), 2u);
  EXPECT_EQ(wrong.errors[0].message,
            "max_length names name, which is not a variable-length array member of exlcm.example_t");
  EXPECT_EQ(wrong.errors[1].message, "max_length 0 of ranges is not 1..65536 (what num_ranges holds)");
}

TEST(LcmTypes, NestedStructsMustBeInTheFileAndNotContainThemselves) {
  const LcmTypeFile file =
      parse_lcm_types("struct a_t { other.b_t b; }\nstruct c_t { d_t d; }\nstruct d_t { c_t c; }\n");
  ASSERT_TRUE(file.ok());
  EXPECT_FALSE(lcm_fingerprint(file, *file.find("a_t")));
  EXPECT_EQ(lcm_channel_type(file, *file.find("a_t")).errors.at(0).message,
            "a_t: struct other.b_t is not defined in the file");
  EXPECT_EQ(lcm_channel_type(file, *file.find("c_t")).errors.at(0).message, "c_t: struct c_t contains itself");
}

TEST(LcmTypes, EveryProblemIsLocated) {
  EXPECT_EQ(lcm_errors("struct t { int32_t a; int16_t b[n]; }"),
            std::vector<std::string>{"1:31: the size of b, 'n', is not an integer member declared before it"});
  EXPECT_EQ(
      lcm_errors("struct t { double d; int8_t x[d]; int8_t y[0]; int8_t d; }"),
      (std::vector<std::string>{"1:29: the size of x, 'd', is not an integer member declared before it",
                                "1:42: array size '0' of y is not 1..65536", "1:55: member d declared twice in t"}));
  EXPECT_EQ(lcm_errors("struct t { const int8_t BIG = 128; const string S = 1; }"),
            (std::vector<std::string>{"1:31: constant BIG = '128' does not fit int8_t",
                                      "1:42: a constant is an integer, float or double, not 'string'"}));
  EXPECT_EQ(lcm_errors("struct t { int32_t a }"),
            std::vector<std::string>{"1:22: expected ';' after the member, found '}'"});
  EXPECT_EQ(lcm_errors("enum e { A=1 }\nstruct t { int8_t a; } /* open"),
            (std::vector<std::string>{
                "1:1: LCM enums (deprecated in lcm-gen) are not read: declare the values as constants of an integer",
                "2:24: unterminated comment: no '*/' before the end of the text"}));
  EXPECT_EQ(lcm_errors("struct t { int8_t a; }\nstruct t { int8_t b; }"),
            std::vector<std::string>{"2:1: struct t defined twice"});
  EXPECT_EQ(lcm_errors("package p\nstruct t { }"),
            std::vector<std::string>{"2:1: expected ';' after the package name, found 'struct'"});
}

}  // namespace
}  // namespace cosmic
