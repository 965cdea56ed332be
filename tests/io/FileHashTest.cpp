// SHA-256 against the FIPS 180-4 example vectors, in memory and from files
// larger than the read buffer.
#include <gtest/gtest.h>

#include <string>

#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/io/FileHash.h"

namespace parcelscope::io {
namespace {

TEST(FileHash, MatchesTheStandardTestVectors) {
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  // 56 bytes: the length no longer fits in the first block.
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(FileHash, FileInManyReadsEqualsTheInMemoryHash) {
  test::TempDir dir;
  const std::string million(1000000, 'a');  // 15+ read buffers
  const auto path = dir.write("a.bin", million);
  EXPECT_EQ(sha256File(path), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  EXPECT_EQ(sha256File(dir.write("abc.txt", "abc")), sha256Hex("abc"));
}

TEST(FileHash, MissingFileIsAnInputErrorNamingIt) {
  test::TempDir dir;
  try {
    sha256File(dir.file("nope.geojson"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Input);
    EXPECT_NE(std::string(e.what()).find("nope.geojson"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace parcelscope::io
