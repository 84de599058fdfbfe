// io/file_access: what a path may name before antpose reads it.
#include "antpose/io/file_access.hpp"

#include <sys/stat.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(FileAccess, OnlyRegularFilesAreRead) {
  test::TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  // A FIFO would block the read until a writer comes; a device would stream without end.
  EXPECT_THAT(test::input_error([&] { read_text(dir / "pipe"); }),
              HasSubstr("pipe: is a FIFO (named pipe), expected a regular file"));
  EXPECT_THAT(test::input_error([&] { read_text("/dev/zero"); }),
              HasSubstr("/dev/zero: is a character device, expected a regular file"));
  EXPECT_THAT(test::input_error([&] { read_text(dir.path()); }), HasSubstr("is a folder, expected a file"));
  EXPECT_THAT(test::input_error([&] { read_text(dir / "none.csv"); }), HasSubstr("none.csv: file not found"));
  fs::create_symlink("loop-b", dir / "loop-a");
  fs::create_symlink("loop-a", dir / "loop-b");
  EXPECT_THAT(test::input_error([&] { read_text(dir / "loop-a"); }), HasSubstr("Too many levels of symbolic links"));
  EXPECT_EQ(file_kind(dir / "pipe"), FileKind::kFifo);
  EXPECT_EQ(file_kind("/dev/null"), FileKind::kCharacterDevice);
}

TEST(FileAccess, AFileLargerThanTheLimitIsRefusedAlsoWhenItOnlyInflatesSo) {
  test::TempDir dir;
  const std::string text(5000, 'a');
  write_text_atomic(dir / "big.txt", text);
  EXPECT_EQ(read_text(dir / "big.txt", 5000), text);
  EXPECT_THAT(test::input_error([&] { read_text(dir / "big.txt", 4000); }), HasSubstr("more than the"));
  // 5000 repeated bytes compress to a few dozen: the limit holds on what comes out.
  write_text_atomic(dir / "big.txt.gz", text);
  ASSERT_LT(fs::file_size(dir / "big.txt.gz"), 100u);
  EXPECT_EQ(read_text(dir / "big.txt.gz", 5000), text);
  EXPECT_THAT(test::input_error([&] { read_text(dir / "big.txt.gz", 4000); }), HasSubstr("once decompressed"));
}

TEST(FileAccess, PathsWrittenInACaptureStayInsideIt) {
  test::TempDir dir;
  const fs::path root = dir / "capture";
  test::write_file(root / "truth" / "orientation.csv", "t,qw,qx,qy,qz\n");
  test::write_file(dir / "secret.txt", "SECRET-LINE\n");
  const CapturePathRef where{root / "capture.yaml", 17, "truth.orientation"};
  EXPECT_EQ(path_inside(root, "truth/orientation.csv", where), root / "truth" / "orientation.csv");
  EXPECT_EQ(path_inside(root, "truth/../truth/orientation.csv", where), root / "truth" / "orientation.csv");
  EXPECT_THAT(test::input_error([&] { path_inside(root, "/dev/zero", where); }),
              HasSubstr("capture.yaml:17: truth.orientation '/dev/zero' is an absolute path"));
  EXPECT_THAT(test::input_error([&] { path_inside(root, "truth/../../secret.txt", where); }),
              HasSubstr("truth.orientation 'truth/../../secret.txt' leads out of the capture folder;"));
  EXPECT_THAT(test::input_error([&] { path_inside(root, "", where); }), HasSubstr("truth.orientation '' is empty"));
  // A link inside the capture may lead elsewhere inside it, never out of it.
  fs::create_symlink("orientation.csv", root / "truth" / "inside.csv");
  EXPECT_EQ(path_inside(root, "truth/inside.csv", where), root / "truth" / "inside.csv");
  fs::create_symlink(dir / "secret.txt", root / "truth" / "outside.csv");
  const std::string message = test::input_error([&] { path_inside(root, "truth/outside.csv", where); });
  EXPECT_THAT(message, HasSubstr("leads out of the capture folder through a symbolic link"));
  EXPECT_THAT(message, Not(HasSubstr("SECRET")));
}

}  // namespace
}  // namespace antpose::io
