// store/provenance and content_digest: a result names the antpose and the inputs behind it.
#include "antpose/store/provenance.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/store/content_hash.hpp"
#include "antpose/version.hpp"
#include "support/test_support.hpp"

namespace antpose::store {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

TEST(ContentDigest, AFolderIsItsFilesNamesAndContentsNotItsPlace) {
  test::TempDir dir;
  test::write_file(dir / "a" / "capture.yaml", "format: antpose-capture\n");
  test::write_file(dir / "a" / "sensors" / "accelerometer.csv", "t,x,y,z\n0,0,0,9.8\n");
  const std::string digest = content_digest(dir / "a");
  EXPECT_EQ(digest.size(), 64u);
  EXPECT_EQ(content_digest(dir / "a" / "capture.yaml"), sha256_bytes("format: antpose-capture\n"));
  fs::copy(dir / "a", dir / "b", fs::copy_options::recursive);
  EXPECT_EQ(content_digest(dir / "b"), digest);  // the same files elsewhere
  test::write_file(dir / "b" / "sensors" / "accelerometer.csv", "t,x,y,z\n0,0,0,9.7\n");
  EXPECT_NE(content_digest(dir / "b"), digest);  // one value changed
  fs::copy(dir / "a", dir / "c", fs::copy_options::recursive);
  fs::rename(dir / "c" / "sensors" / "accelerometer.csv", dir / "c" / "sensors" / "gyroscope.csv");
  EXPECT_NE(content_digest(dir / "c"), digest);  // the same bytes under another name
  EXPECT_EQ(sha256_bytes("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");  // FIPS 180-2
}

TEST(Provenance, NamesThisAntposeTheInputsAndTheOptions) {
  test::TempDir dir;
  test::write_file(dir / "capture" / "capture.yaml", "format: antpose-capture\n");
  Provenance p = Provenance::now("measure").input("capture", dir / "capture");
  p.device_id = "px7";
  p.options["--roi"] = "images/a.jpg:1,2,30,40";
  const auto j = to_json(p);
  EXPECT_THAT(j["antpose"].get<std::string>(), StartsWith(std::string(kVersion) + " ("));
  EXPECT_EQ(j["command"], "measure");
  EXPECT_THAT(j["created_utc"].get<std::string>(), HasSubstr("T"));
  ASSERT_EQ(j["inputs"].size(), 1u);
  EXPECT_EQ(j["inputs"][0]["role"], "capture");
  EXPECT_EQ(j["inputs"][0]["sha256"], content_digest(dir / "capture"));
  EXPECT_EQ(j["device"]["id"], "px7");
  EXPECT_TRUE(j["site"].is_null());
  EXPECT_EQ(j["options"]["--roi"], "images/a.jpg:1,2,30,40");
  EXPECT_FALSE(build_revision().empty());
}

}  // namespace
}  // namespace antpose::store
