#include "parcelscope/core/Json.h"

#include <gtest/gtest.h>

namespace parcelscope {
namespace {

TEST(Json, KeepsKeyOrderAndEscapesStrings) {
  Json j = Json::object().set("b", 1).set("a", "x\"y\n").set("c", Json::array().push(1.5).push(true));
  EXPECT_EQ(j.dump(-1), R"({"b":1,"a":"x\"y\n","c":[1.5,true]})");
}

TEST(Json, SetReplacesExistingKeyAndNonFiniteIsNull) {
  Json j = Json::object().set("a", 1).set("a", 1.0 / 0.0);
  EXPECT_EQ(j.dump(-1), R"({"a":null})");
}

}  // namespace
}  // namespace parcelscope
