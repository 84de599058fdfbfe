// Whole-file text I/O with transparent gzip (zlib), and crash-safe writes.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace antpose::io {

/// Reads a file; a gzip-compressed file (any name) is decompressed transparently.
/// Throws InputError naming the file when it is missing, a folder, unreadable or corrupt.
std::string read_text(const std::filesystem::path& file);

/// Writes `content` to `file` so that a reader never sees a half-written file and an existing
/// file is replaced only once the new one is complete (temporary file + rename). A name ending
/// in ".gz" is gzip-compressed. Throws antpose::Error on failure, leaving `file` untouched.
void write_text_atomic(const std::filesystem::path& file, std::string_view content);

/// Fills a new folder and puts it at `folder` only once `fill` has returned: `fill` writes into
/// a temporary sibling, which then replaces `folder` by rename (an existing `folder` only when
/// `overwrite`; it is removed after the new one is in place). On an exception the temporary
/// folder is removed and `folder` is untouched. InputError when `folder` exists and !overwrite.
void write_folder_atomic(const std::filesystem::path& folder, bool overwrite,
                         const std::function<void(const std::filesystem::path& tmp)>& fill);

/// True when the path names a gzip file by its suffix.
bool is_gzip_name(const std::filesystem::path& file);

}  // namespace antpose::io
