// Parameter descriptions: ranges are enforced, lists of two algorithms merge
// without listing a shared parameter twice, enums and booleans read their
// labels, and lists fall into their groups.
#include <gtest/gtest.h>

#include <stdexcept>

#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parameter.h"

namespace parcelscope {
namespace {

TEST(Parameters, AppendKeepsTheFirstDescriptionOfASharedName) {
  std::vector<ParameterDescription> a = {realParameter("k", "first", "", 0, 10, 2, "Bounds"),
                                         realParameter("min-frontage", "from a", "m", 0, 5, 1, "Blocks")};
  const std::vector<ParameterDescription> b = {realParameter("min-frontage", "from b", "m", 0, 9, 3, "Blocks"),
                                               integerParameter("seed", "", "", 0, 9, 1, "Subdivision")};
  appendParameters(a, b);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[1].help, "from a");
  EXPECT_EQ(a[2].name, "seed");
  EXPECT_EQ(defaultValues(a).at("min-frontage"), 1.0);
}

TEST(Parameters, ValuesOutsideTheRangeOrNotIntegerAreUsageErrors) {
  const ParameterDescription bins = integerParameter("bins", "", "", 2, 500, 30, "Comparison");
  EXPECT_TRUE(bins.integer());
  EXPECT_NO_THROW(checkValue(bins, 2));
  EXPECT_THROW(checkValue(bins, 1), Error);
  EXPECT_THROW(checkValue(bins, 2.5), Error);
  EXPECT_FALSE(realParameter("k", "", "", 0, 10, 2, "Bounds").integer());
}

const ParameterDescription kCornerRule =
    enumParameter("corner-rule", "which street", {"street-width", "street-length"}, "street-length", "Skeleton");

TEST(Parameters, AnEnumRangesOverItsLabelsAndDefaultsToTheNumberOfItsDefaultLabel) {
  EXPECT_EQ(kCornerRule.kind, ParameterKind::Enum);
  EXPECT_EQ(kCornerRule.minimum, 0.0);
  EXPECT_EQ(kCornerRule.maximum, 1.0);
  EXPECT_EQ(kCornerRule.defaultValue, 1.0);
  EXPECT_TRUE(kCornerRule.integer());
  EXPECT_EQ(kCornerRule.group, "Skeleton");
  EXPECT_THROW(enumParameter("e", "", {"a", "b"}, "c", "G"), std::logic_error);
}

TEST(Parameters, AnEnumTakesItsLabelsAndTheirNumbers) {
  EXPECT_EQ(parseValue(kCornerRule, "street-width"), 0.0);
  EXPECT_EQ(parseValue(kCornerRule, "street-length"), 1.0);
  EXPECT_EQ(parseValue(kCornerRule, "1"), 1.0);
  EXPECT_EQ(parseValue(kCornerRule, "0"), 0.0);
  EXPECT_THROW(parseValue(kCornerRule, "2"), Error);
  EXPECT_THROW(parseValue(kCornerRule, "0.5"), Error);
  try {
    parseValue(kCornerRule, "widest");
    FAIL() << "an unknown label was taken";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Usage);
    const std::string m = e.what();
    EXPECT_NE(m.find("--corner-rule widest"), std::string::npos) << m;
    EXPECT_NE(m.find("street-width, street-length"), std::string::npos) << m;
  }
  EXPECT_EQ(formatValue(kCornerRule, 0), "street-width");
  EXPECT_EQ(formatValue(kCornerRule, 1), "street-length");
}

TEST(Parameters, ABooleanTakesZeroOneTrueFalseYesNo) {
  const ParameterDescription figures = booleanParameter("figures", "render", true, "Figures");
  EXPECT_EQ(figures.kind, ParameterKind::Boolean);
  EXPECT_EQ(figures.defaultValue, 1.0);
  EXPECT_EQ(booleanParameter("patio-obb", "", false, "Skeleton").defaultValue, 0.0);
  for (const char* yes : {"1", "true", "yes", "Yes", "TRUE"}) EXPECT_EQ(parseValue(figures, yes), 1.0) << yes;
  for (const char* no : {"0", "false", "no", "No", "FALSE"}) EXPECT_EQ(parseValue(figures, no), 0.0) << no;
  for (const char* bad : {"2", "0.5", "maybe", ""}) EXPECT_THROW(parseValue(figures, bad), Error) << bad;
  EXPECT_EQ(formatValue(figures, 1), "yes");
  EXPECT_EQ(formatValue(figures, 0), "no");
}

TEST(Parameters, NumbersAreParsedAsBeforeAndOnlyNumbers) {
  const ParameterDescription k = realParameter("k", "", "", 0, 10, 2, "Bounds");
  EXPECT_EQ(parseValue(k, "2.5"), 2.5);
  EXPECT_EQ(parseValue(k, "1e-1"), 0.1);
  EXPECT_THROW(parseValue(k, "yes"), Error);
  EXPECT_THROW(parseValue(k, ""), Error);
  EXPECT_THROW(parseValue(k, "11"), Error);
  const ParameterDescription seed = integerParameter("seed", "", "", 0, 4294967295.0, 1, "Subdivision");
  EXPECT_EQ(parseValue(seed, "4294967295"), 4294967295.0);
  EXPECT_THROW(parseValue(seed, "1.5"), Error);
  EXPECT_EQ(formatValue(seed, 4294967295.0), "4294967295");
  EXPECT_EQ(formatValue(k, 0.3), "0.3");
}

// The message of a refused value, or "" when it was taken.
std::string refusal(const ParameterDescription& d, const std::string& text) {
  try {
    parseValue(d, text);
    return "";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Usage) << e.what();
    return e.what();
  }
}

TEST(Parameters, RefusedValuesAndRangesArePrintedExactly) {
  const ParameterDescription seed = integerParameter("seed", "", "", 0, 4294967295.0, 1, "Subdivision");
  EXPECT_EQ(refusal(seed, "5000000000"), "--seed 5000000000 is outside [0, 4294967295]");
  EXPECT_EQ(refusal(seed, "4294967296"), "--seed 4294967296 is outside [0, 4294967295]");
  EXPECT_EQ(refusal(seed, "-1"), "--seed -1 is outside [0, 4294967295]");
  EXPECT_EQ(refusal(seed, "1234567.5"), "--seed 1234567.5 must be an integer");
  const ParameterDescription aMin = realParameter("a-min", "", "m2", 0, 1e8, 200, "Bounds");
  EXPECT_EQ(refusal(aMin, "100000000.25"), "--a-min 100000000.25 is outside [0, 100000000] m2");
  EXPECT_EQ(refusal(aMin, "1e300"), "--a-min 1e+300 is outside [0, 100000000] m2");
  EXPECT_EQ(refusal(aMin, "-0.1"), "--a-min -0.1 is outside [0, 100000000] m2");
  EXPECT_EQ(refusal(aMin, "123456789"), "--a-min 123456789 is outside [0, 100000000] m2");
  const ParameterDescription k = realParameter("k", "", "", 0.1, 10, 2, "Bounds");
  EXPECT_EQ(refusal(k, "0.05"), "--k 0.05 is outside [0.1, 10]");
}

TEST(Parameters, OutputOnlyMarksADescriptionAndEqualityComparesEveryField) {
  const ParameterDescription w = integerParameter("figure-width", "Width", "px", 200, 10000, 1800, "Figures");
  EXPECT_FALSE(w.outputOnly);
  const ParameterDescription o = outputOnly(w);
  EXPECT_TRUE(o.outputOnly);
  EXPECT_NE(o, w);
  EXPECT_EQ(outputOnly(w), o);
  ParameterDescription other = w;
  other.group = "Output";
  EXPECT_NE(other, w);
  other = w;
  other.help = "Height";
  EXPECT_NE(other, w);
}

TEST(Parameters, GroupsComeInTheOrderTheyFirstAppearWithTheirMembersInListOrder) {
  const std::vector<ParameterDescription> list = {realParameter("block-tolerance", "", "m", 0, 50, 1, "Blocks"),
                                                  realParameter("k", "", "", 0, 10, 2, "Bounds"),
                                                  realParameter("min-frontage", "", "m", 0, 1000, 1, "Blocks"),
                                                  kCornerRule, realParameter("a-min", "", "m2", 0, 1e8, 200, "Bounds")};
  const auto groups = groupParameters(list);
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0].first, "Blocks");
  EXPECT_EQ(groups[1].first, "Bounds");
  EXPECT_EQ(groups[2].first, "Skeleton");
  ASSERT_EQ(groups[0].second.size(), 2u);
  EXPECT_EQ(groups[0].second[1].name, "min-frontage");
  ASSERT_EQ(groups[1].second.size(), 2u);
  EXPECT_EQ(groups[1].second[0].name, "k");
  EXPECT_EQ(groups[1].second[1].name, "a-min");
}

}  // namespace
}  // namespace parcelscope
