// write_folder_atomic: a folder appears whole or not at all, and never replaces data unasked.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::size_t entries(const fs::path& folder) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(folder), fs::directory_iterator()));
}

TEST(FolderAtomic, AppearsWholeAndKeepsDataOnFailure) {
  test::TempDir dir;
  const fs::path out = dir / "report";
  write_folder_atomic(out, false, [](const fs::path& tmp) { write_text_atomic(tmp / "a.txt", "first"); });
  EXPECT_EQ(read_text(out / "a.txt"), "first");

  // Not replaced unless asked.
  EXPECT_THAT(test::input_error([&] { write_folder_atomic(out, false, [](const fs::path&) {}); }),
              HasSubstr("already exists"));
  // A failure half-way leaves the old folder as it was and no temporary folder behind.
  EXPECT_THROW(write_folder_atomic(out, true,
                                   [](const fs::path& tmp) {
                                     write_text_atomic(tmp / "a.txt", "second");
                                     throw Error("disk full");
                                   }),
               Error);
  EXPECT_EQ(read_text(out / "a.txt"), "first");
  EXPECT_EQ(entries(dir.path()), 1u);
  // Replaced when asked and the new content is complete.
  write_folder_atomic(out, true, [](const fs::path& tmp) { write_text_atomic(tmp / "b.txt", "new"); });
  EXPECT_FALSE(fs::exists(out / "a.txt"));
  EXPECT_EQ(read_text(out / "b.txt"), "new");
  EXPECT_EQ(entries(dir.path()), 1u);
}

}  // namespace
}  // namespace antpose::io
