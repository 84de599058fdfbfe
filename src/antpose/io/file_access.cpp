#include "antpose/io/file_access.hpp"

#include <fmt/format.h>

#include "antpose/core/error.hpp"

namespace antpose::io {
namespace fs = std::filesystem;

FileKind file_kind(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
    throw InputError(path, fmt::format("cannot be examined ({})", ec.message()));
  switch (status.type()) {
    case fs::file_type::not_found:
      return FileKind::kMissing;
    case fs::file_type::regular:
      return FileKind::kRegular;
    case fs::file_type::directory:
      return FileKind::kDirectory;
    case fs::file_type::character:
      return FileKind::kCharacterDevice;
    case fs::file_type::fifo:
      return FileKind::kFifo;
    default:
      return FileKind::kOther;
  }
}

std::string describe(FileKind kind) {
  switch (kind) {
    case FileKind::kMissing:
      return "missing";
    case FileKind::kRegular:
      return "a regular file";
    case FileKind::kDirectory:
      return "a folder";
    case FileKind::kCharacterDevice:
      return "a character device";
    case FileKind::kFifo:
      return "a FIFO (named pipe)";
    case FileKind::kOther:
      return "a socket or block device";
  }
  return "unknown";
}

void require_regular_file(const fs::path& file, std::uintmax_t max_bytes) {
  const FileKind kind = file_kind(file);
  if (kind == FileKind::kMissing) throw InputError(file, "file not found");
  if (kind == FileKind::kDirectory) throw InputError(file, "is a folder, expected a file");
  if (kind != FileKind::kRegular) throw InputError(file, fmt::format("is {}, expected a regular file", describe(kind)));
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(file, ec);
  if (!ec && size > max_bytes)
    throw InputError(file, fmt::format("is {:.1f} MB, more than the {:.0f} MB antpose reads from one file", size / 1e6,
                                       max_bytes / 1e6));
}

namespace {

// True when `inner` is `outer` or below it (both absolute and free of "..", links resolved).
bool is_within_folder(const fs::path& inner, const fs::path& outer) {
  const fs::path up = inner.lexically_relative(outer);
  return !up.empty() && *up.begin() != "..";
}

}  // namespace

fs::path path_inside(const fs::path& root, std::string_view relative, const CapturePathRef& where) {
  const auto refuse = [&](const std::string& why) {
    return InputError(where.source, where.line,
                      fmt::format("{} '{}' {}; paths in a capture are relative to its folder and stay inside it",
                                  where.key, relative, why));
  };
  if (relative.empty()) throw refuse("is empty");
  const fs::path rel(relative);
  if (rel.is_absolute() || rel.has_root_name()) throw refuse("is an absolute path");
  const fs::path normal = rel.lexically_normal();
  if (!normal.empty() && *normal.begin() == "..") throw refuse("leads out of the capture folder");
  const fs::path path = root / normal;
  std::error_code ec;
  const fs::path real_root = fs::weakly_canonical(root, ec);
  const fs::path real_path = ec ? fs::path() : fs::weakly_canonical(path, ec);
  if (ec) throw refuse(fmt::format("cannot be resolved ({})", ec.message()));
  if (!is_within_folder(real_path, real_root)) throw refuse("leads out of the capture folder through a symbolic link");
  return path;
}

}  // namespace antpose::io
