#include "parcelscope/core/Keys.h"

#include <gtest/gtest.h>

#include <set>

namespace parcelscope {
namespace {

TEST(Keys, FnvOfKnownBytesMatchesTheReferenceValues) {
  // FNV-1a 64 test vectors (Fowler, Noll, Vo).
  EXPECT_EQ(hashBytes(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(hashBytes("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(hashBytes("foobar"), 0x85944171f73967e8ull);
}

TEST(Keys, TextRoundTripsAndOnlySixteenHexDigitsParse) {
  for (const Key k : {Key{0}, Key{1}, Key{0xcbf29ce484222325ull}, ~Key{0}}) {
    EXPECT_EQ(keyText(k).size(), 16u);
    EXPECT_EQ(parseKey(keyText(k)), k);
  }
  EXPECT_EQ(parseKey("CBF29CE484222325"), Key{0xcbf29ce484222325ull});
  EXPECT_FALSE(parseKey("cbf29ce48422232"));    // 15 digits
  EXPECT_FALSE(parseKey("cbf29ce4842223250"));  // 17 digits
  EXPECT_FALSE(parseKey("cbf29ce48422232g"));
  EXPECT_FALSE(parseKey(""));
}

TEST(Keys, SetKeysIgnoreOrderButNotMembers) {
  const Key a = hashBytes("a"), b = hashBytes("b"), c = hashBytes("c");
  EXPECT_EQ(setKey({a, b, c}), setKey({c, a, b}));
  EXPECT_NE(setKey({a, b}), setKey({a, b, c}));
  EXPECT_NE(setKey({a, b}), setKey({a, c}));
  EXPECT_EQ(setKey({}), 0u);
}

TEST(Keys, PartZeroKeepsTheFeatureKeyAndOtherPartsDiffer) {
  const Key f = hashBytes("feature");
  EXPECT_EQ(partKey(f, 0), f);
  std::set<Key> parts;
  for (int p = 0; p < 100; ++p) parts.insert(partKey(f, p));
  EXPECT_EQ(parts.size(), 100u);
}

}  // namespace
}  // namespace parcelscope
