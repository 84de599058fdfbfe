// Whole-file text I/O with transparent gzip (zlib), and crash-safe writes.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "antpose/io/file_access.hpp"

namespace antpose::io {

/// Reads a file; a gzip-compressed file (any name) is decompressed transparently.
/// Throws InputError naming the file when it is missing, not a regular file (a folder, a FIFO,
/// a device), larger than `max_bytes` (after decompression), unreadable or corrupt.
std::string read_text(const std::filesystem::path& file, std::uintmax_t max_bytes = kMaxTextBytes);

/// Writes `content` to `file`, the one output contract of antpose. A name ending in ".gz" is
/// gzip-compressed. Symbolic links are followed to the file they name, which is written:
/// - a regular file (or none yet) is replaced only once the new one is complete (temporary file
///   in its folder + rename, keeping its permissions), so a reader never sees half a file;
/// - /dev/stdout, /dev/stderr and /dev/fd/N are written to that open descriptor;
/// - a character device or FIFO (a terminal, a named pipe) is written in place, never replaced;
/// - anything else (a folder, a socket) is refused.
/// Throws OutputError naming `file` (a full disk, a folder without write permission), leaving
/// a replaced file untouched.
void write_text_atomic(const std::filesystem::path& file, std::string_view content);

/// Writes every byte of `bytes` to the open descriptor `fd`; OutputError naming `shown` with the
/// reason when it cannot (a full disk, a closed pipe).
void write_descriptor(int fd, std::string_view bytes, const std::filesystem::path& shown);

/// Fills a new folder and puts it at `folder` (at the folder a symbolic link names) only once `fill` has returned: `fill` writes into
/// a temporary sibling, which then replaces `folder` by rename (an existing `folder` only when
/// `overwrite`; it is removed after the new one is in place). On an exception the temporary
/// folder is removed and `folder` is untouched. InputError when `folder` exists and !overwrite.
void write_folder_atomic(const std::filesystem::path& folder, bool overwrite,
                         const std::function<void(const std::filesystem::path& tmp)>& fill);

/// True when the path names a gzip file by its suffix.
bool is_gzip_name(const std::filesystem::path& file);

}  // namespace antpose::io
