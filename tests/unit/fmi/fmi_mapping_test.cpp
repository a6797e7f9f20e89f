// The mapping table (cosmic/fmi_mapping.hpp, docs/fmu.md): which FMU variable types carry which
// channel field kinds in which direction, ranges of integers and enumerations included, and which
// texts a parameter takes.
#include <gtest/gtest.h>

#include "cosmic/fmi_description.hpp"
#include "cosmic/fmi_mapping.hpp"
#include "fmu_test_support.hpp"

namespace cosmic::fmi {
namespace {

TypeField scalar_field(ScalarKind kind, std::optional<double> min = {}, std::optional<double> max = {}) {
  TypeField f{"f", {}, {}, min, max, {}};
  f.type.scalar = kind;
  return f;
}

TypeField enum_field(std::vector<EnumValue> values) {
  TypeField f{"f", {}, {}, {}, {}, {}};
  f.type.kind = FieldType::Kind::enumeration;
  f.type.scalar = ScalarKind::uint8;
  f.type.values = std::move(values);
  return f;
}

class FmiMapping : public testing::Test {
 protected:
  void SetUp() override {
    const DescriptionResult two = parse_model_description(test::kFmi2Description);
    const DescriptionResult three = parse_model_description(test::kFmi3Description);
    ASSERT_TRUE(two.ok() && three.ok());
    fmi2_ = two.description;
    fmi3_ = three.description;
  }
  const Variable& v2(const char* name) const { return *fmi2_.find_variable(name); }
  const Variable& v3(const char* name) const { return *fmi3_.find_variable(name); }

  FmuDescription fmi2_;
  FmuDescription fmi3_;
};

TEST_F(FmiMapping, FloatsCarryFloatAndIntegerFields) {
  for (const ScalarKind kind : {ScalarKind::float32, ScalarKind::float64, ScalarKind::int16, ScalarKind::uint64}) {
    EXPECT_EQ(mapping_problem(v2("y"), fmi2_, scalar_field(kind), Flow::output), "");
    EXPECT_EQ(mapping_problem(v3("f32"), fmi3_, scalar_field(kind), Flow::input), "");
  }
  EXPECT_NE(mapping_problem(v2("y"), fmi2_, scalar_field(ScalarKind::boolean), Flow::output), "");
}

TEST_F(FmiMapping, IntegersNeedEveryValueThatFlowsToFit) {
  // count: Integer declared 0..200: fits uint8 and int16 on the way out, not int8.
  EXPECT_EQ(mapping_problem(v2("count"), fmi2_, scalar_field(ScalarKind::uint8), Flow::output), "");
  EXPECT_NE(mapping_problem(v2("count"), fmi2_, scalar_field(ScalarKind::int8), Flow::output).find("do not all fit"),
            std::string::npos);
  // u32 without a declared range: all of uint32 needs uint32 or wider.
  EXPECT_NE(mapping_problem(v3("u32"), fmi3_, scalar_field(ScalarKind::int32), Flow::output), "");
  EXPECT_EQ(mapping_problem(v3("u32"), fmi3_, scalar_field(ScalarKind::int64), Flow::output), "");
  // A field declared narrower than what the variable may hold does not take it either.
  EXPECT_NE(mapping_problem(v3("u32"), fmi3_, scalar_field(ScalarKind::int64, 0, 1000), Flow::output), "");
  // i8 input: a uint8 field's 0..255 does not fit Int8, its declared 0..100 does.
  EXPECT_NE(mapping_problem(v3("i8"), fmi3_, scalar_field(ScalarKind::uint8), Flow::input), "");
  EXPECT_EQ(mapping_problem(v3("i8"), fmi3_, scalar_field(ScalarKind::uint8, 0, 100), Flow::input), "");
  // Integers go out to float fields, but never come in from them.
  EXPECT_EQ(mapping_problem(v3("i32"), fmi3_, scalar_field(ScalarKind::float64), Flow::output), "");
  EXPECT_NE(mapping_problem(v3("i64"), fmi3_, scalar_field(ScalarKind::float64), Flow::input).find("not whole numbers"),
            std::string::npos);
}

TEST_F(FmiMapping, EnumerationsBooleansStringsAndWhatIsNeverMapped) {
  // gear: park=0, drive=1, reverse=-1.
  EXPECT_EQ(mapping_problem(v3("gear"), fmi3_, enum_field({{"P", 0}, {"D", 1}, {"R", -1}, {"N", 2}}), Flow::output),
            "");
  EXPECT_NE(mapping_problem(v3("gear"), fmi3_, enum_field({{"P", 0}, {"D", 1}}), Flow::output).find("reverse=-1"),
            std::string::npos);
  EXPECT_NE(mapping_problem(v3("gear"), fmi3_, enum_field({{"P", 0}, {"D", 1}, {"R", -1}, {"N", 2}}), Flow::input)
                .find("N=2"),
            std::string::npos);
  EXPECT_EQ(mapping_problem(v3("gear"), fmi3_, scalar_field(ScalarKind::int8), Flow::output), "");
  EXPECT_NE(mapping_problem(v3("gear"), fmi3_, scalar_field(ScalarKind::uint8), Flow::output), "");  // -1
  EXPECT_EQ(mapping_problem(v3("gear"), fmi3_, scalar_field(ScalarKind::int8, -1, 1), Flow::input), "");
  EXPECT_EQ(mapping_problem(v2("ready"), fmi2_, scalar_field(ScalarKind::boolean), Flow::output), "");
  EXPECT_NE(mapping_problem(v2("ready"), fmi2_, scalar_field(ScalarKind::uint8), Flow::output), "");
  TypeField text{"t", {}, {}, {}, {}, {}};
  text.type.kind = FieldType::Kind::string;
  text.type.bound = 16;
  EXPECT_EQ(mapping_problem(v2("label"), fmi2_, text, Flow::input), "");
  EXPECT_NE(mapping_problem(v2("y"), fmi2_, text, Flow::output), "");
  EXPECT_NE(mapping_problem(v3("blob"), fmi3_, scalar_field(ScalarKind::uint8), Flow::output).find("not mapped"),
            std::string::npos);
  EXPECT_NE(mapping_problem(v3("tick"), fmi3_, scalar_field(ScalarKind::boolean), Flow::input).find("not mapped"),
            std::string::npos);
  EXPECT_NE(mapping_problem(v3("vector"), fmi3_, scalar_field(ScalarKind::float64), Flow::output).find("array"),
            std::string::npos);
  TypeField record{"r", {}, {}, {}, {}, {}};
  record.type.kind = FieldType::Kind::record;
  record.type.fields = {scalar_field(ScalarKind::float64)};
  EXPECT_NE(mapping_problem(v2("y"), fmi2_, record, Flow::output).find("map a number"), std::string::npos);
}

TEST_F(FmiMapping, ParametersTakeValuesOfTheirType) {
  EXPECT_EQ(parameter_problem(v2("gain"), fmi2_, "2.5"), "");
  EXPECT_NE(parameter_problem(v2("gain"), fmi2_, "10.5").find("outside the variable's range 0..10"), std::string::npos);
  EXPECT_NE(parameter_problem(v2("gain"), fmi2_, "fast"), "");
  EXPECT_EQ(parameter_problem(v2("count"), fmi2_, "200"), "");
  EXPECT_NE(parameter_problem(v2("count"), fmi2_, "201"), "");
  EXPECT_NE(parameter_problem(v2("count"), fmi2_, "2.5"), "");
  EXPECT_EQ(parameter_problem(v3("u64"), fmi3_, "18446744073709551615"), "");
  EXPECT_EQ(parameter_problem(v3("i8"), fmi3_, "-128"), "");
  EXPECT_NE(parameter_problem(v3("i8"), fmi3_, "-129"), "");
  EXPECT_EQ(parameter_problem(v3("flag"), fmi3_, "true"), "");
  EXPECT_NE(parameter_problem(v3("flag"), fmi3_, "yes"), "");
  EXPECT_EQ(parameter_problem(v3("gear"), fmi3_, "reverse"), "");
  EXPECT_EQ(parameter_problem(v3("gear"), fmi3_, "-1"), "");
  EXPECT_NE(parameter_problem(v3("gear"), fmi3_, "7").find("park=0, drive=1, reverse=-1"), std::string::npos);
  EXPECT_EQ(parameter_problem(v3("text"), fmi3_, "any text"), "");
  EXPECT_NE(parameter_problem(v3("blob"), fmi3_, "00ff"), "");
  EXPECT_NE(parameter_problem(v3("vector"), fmi3_, "1"), "");
}

}  // namespace
}  // namespace cosmic::fmi
