// Parameter descriptions: ranges are enforced, and lists of two algorithms
// merge without listing a shared parameter twice.
#include <gtest/gtest.h>

#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parameter.h"

namespace parcelscope {
namespace {

TEST(Parameters, AppendKeepsTheFirstDescriptionOfASharedName) {
  std::vector<ParameterDescription> a = {{"k", "first", "", 0, 10, 2}, {"min-frontage", "from a", "m", 0, 5, 1}};
  const std::vector<ParameterDescription> b = {{"min-frontage", "from b", "m", 0, 9, 3},
                                               {"seed", "", "", 0, 9, 1, true}};
  appendParameters(a, b);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[1].help, "from a");
  EXPECT_EQ(a[2].name, "seed");
  EXPECT_EQ(defaultValues(a).at("min-frontage"), 1.0);
}

TEST(Parameters, ValuesOutsideTheRangeOrNotIntegerAreUsageErrors) {
  const ParameterDescription bins{"bins", "", "", 2, 500, 30, true};
  EXPECT_NO_THROW(checkValue(bins, 2));
  EXPECT_THROW(checkValue(bins, 1), Error);
  EXPECT_THROW(checkValue(bins, 2.5), Error);
}

}  // namespace
}  // namespace parcelscope
