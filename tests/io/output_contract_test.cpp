// write_text_atomic: the one output contract (a file replaced whole, a link written through, a
// device or FIFO written in place, the rest refused).
#include <sys/stat.h>

#include <fstream>
#include <iterator>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

template <class F>
std::string output_error(F&& f) {
  return test::error_message<OutputError>(std::forward<F>(f));
}

TEST(OutputContract, ARegularFileIsReplacedWholeAndKeepsItsPermissions) {
  test::TempDir dir;
  const fs::path file = dir / "result.json";
  write_text_atomic(file, "old\n");
  fs::permissions(file, fs::perms::owner_read | fs::perms::owner_write);
  write_text_atomic(file, "new\n");
  EXPECT_EQ(read_text(file), "new\n");
  EXPECT_EQ(fs::status(file).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);  // no temporary left
}

TEST(OutputContract, ASymbolicLinkIsWrittenThroughAndStaysALink) {
  test::TempDir dir;
  fs::create_directories(dir / "real");
  write_text_atomic(dir / "real" / "result.json", "old\n");
  fs::create_symlink("real/result.json", dir / "link.json");
  write_text_atomic(dir / "link.json", "new\n");
  EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
  EXPECT_EQ(read_text(dir / "real" / "result.json"), "new\n");
  // A dangling link: the file it names is created.
  fs::create_symlink("real/later.json", dir / "later.json");
  write_text_atomic(dir / "later.json", "made\n");
  EXPECT_TRUE(fs::is_symlink(dir / "later.json"));
  EXPECT_EQ(read_text(dir / "real" / "later.json"), "made\n");
  // A symlinked report folder: the folder it names is replaced, the link kept.
  fs::create_directories(dir / "reports" / "site");
  fs::create_directory_symlink("reports/site", dir / "report");
  write_folder_atomic(dir / "report", true, [](const fs::path& tmp) { write_text_atomic(tmp / "index.html", "x"); });
  EXPECT_TRUE(fs::is_symlink(dir / "report"));
  EXPECT_EQ(read_text(dir / "reports" / "site" / "index.html"), "x");
}

TEST(OutputContract, DevicesAndFifosAreWrittenInPlace) {
  write_text_atomic("/dev/null", "nothing\n");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  test::TempDir dir;
  const fs::path pipe = dir / "pipe";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] {
    std::ifstream in(pipe, std::ios::binary);
    received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  });
  write_text_atomic(pipe, "through the pipe\n");
  reader.join();
  EXPECT_EQ(received, "through the pipe\n");
  EXPECT_TRUE(fs::is_fifo(pipe));
}

TEST(OutputContract, WhatCannotTakeTheOutputIsRefusedByName) {
  test::TempDir dir;
  fs::create_directories(dir / "folder");
  EXPECT_THAT(output_error([&] { write_text_atomic(dir / "folder", "x"); }),
              HasSubstr("folder: is a folder; give a file name for the output"));
  EXPECT_THAT(output_error([&] { write_text_atomic("/dev/full", "x"); }),
              HasSubstr("/dev/full: cannot write (No space left on device)"));
  test::write_file(dir / "file", "x");
  EXPECT_THAT(output_error([&] { write_text_atomic(dir / "file" / "below.json", "x"); }),
              HasSubstr("cannot create its folder"));
  EXPECT_THAT(output_error([&] { write_folder_atomic(dir / "file", true, [](const fs::path&) {}); }),
              HasSubstr("file: is a regular file, expected a folder"));
}

TEST(OutputContract, AGzipNameIsCompressed) {
  test::TempDir dir;
  write_text_atomic(dir / "s.csv.gz", "t,x\n1,2\n");
  std::ifstream in(dir / "s.csv.gz", std::ios::binary);
  EXPECT_EQ(in.get(), 0x1f);  // gzip magic
  EXPECT_EQ(read_text(dir / "s.csv.gz"), "t,x\n1,2\n");
}

}  // namespace
}  // namespace antpose::io
