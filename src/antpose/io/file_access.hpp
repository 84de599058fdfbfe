// What a path may name before antpose reads from it or writes to it.
//
// Every reader checks its file here first, so that a FIFO never blocks a read, a device never
// streams without end into memory, and a path written inside a capture never leads out of it
// (a capture is data from elsewhere; its paths must not make antpose read, or echo, /etc/shadow).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace antpose::io {

/// What a path names once its symbolic links are followed.
enum class FileKind { kMissing, kRegular, kDirectory, kCharacterDevice, kFifo, kOther };

/// The kind of `path`, following symbolic links. InputError naming the path when it cannot be
/// told: a loop of symbolic links, a folder on the way that may not be searched.
FileKind file_kind(const std::filesystem::path& path);

/// "a folder", "a FIFO (named pipe)", … for messages.
std::string describe(FileKind kind);

/// The largest file a text reader takes (bytes, after decompression): ten times the longest
/// stream a phone records in an hour at 500 Hz, far below the memory of a laptop.
inline constexpr std::uintmax_t kMaxTextBytes = std::uintmax_t{1} << 30;

/// Throws InputError naming `file` unless it is a regular file (symbolic links followed) of at
/// most `max_bytes`: missing, a folder, a FIFO or a device are each said as such.
void require_regular_file(const std::filesystem::path& file, std::uintmax_t max_bytes = kMaxTextBytes);

/// Where a path written in a capture's files leads, checked to stay inside the capture.
struct CapturePathRef {
  std::filesystem::path source;  // the file that holds the path (capture.yaml, shots.csv)
  std::size_t line = 0;          // its 1-based line there, 0 when unknown
  std::string_view key;          // the key or column that holds it ("truth.orientation", "image")
};

/// `root / relative`, refusing an empty or absolute path, one whose ".." leave `root`, and one
/// whose symbolic links lead out of `root`. The message names `where` and the value, never the
/// content of the file the path names.
std::filesystem::path path_inside(const std::filesystem::path& root, std::string_view relative,
                                  const CapturePathRef& where);

}  // namespace antpose::io
