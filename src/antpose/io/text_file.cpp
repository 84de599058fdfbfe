#include "antpose/io/text_file.hpp"

#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>

#include <fmt/format.h>

#include "antpose/core/error.hpp"

namespace antpose::io {
namespace fs = std::filesystem;

bool is_gzip_name(const fs::path& file) { return file.extension() == ".gz"; }

std::string read_text(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(file, "file not found");
  if (fs::is_directory(file, ec)) throw InputError(file, "is a folder, expected a file");
  // gzread passes plain files through unchanged, so one path serves .csv and .csv.gz.
  gzFile gz = gzopen(file.c_str(), "rb");
  if (gz == nullptr) throw InputError(file, fmt::format("cannot open for reading ({})", std::strerror(errno)));
  std::string out;
  char buffer[1 << 16];
  for (;;) {
    const int n = gzread(gz, buffer, sizeof buffer);
    if (n < 0) {
      int code = 0;
      const std::string what = gzerror(gz, &code);
      const std::string why = code == Z_ERRNO ? std::string(std::strerror(errno)) : what;
      gzclose(gz);
      if (is_gzip_name(file)) throw InputError(file, "corrupt or truncated gzip data (" + why + ")");
      throw InputError(file, "cannot read: " + why);
    }
    // gzread passes plain data through; a .gz name with plain content is a mislabelled file.
    if (out.empty() && is_gzip_name(file) && gzdirect(gz) == 1) {
      gzclose(gz);
      throw InputError(file, "corrupt gzip data: the file has a .gz name but no gzip header");
    }
    if (n == 0) break;
    out.append(buffer, static_cast<std::size_t>(n));
  }
  if (gzclose(gz) != Z_OK && is_gzip_name(file)) throw InputError(file, "corrupt or truncated gzip data");
  return out;
}

namespace {

fs::path temporary_sibling(const fs::path& file) {
  std::random_device rd;
  return file.parent_path() / fmt::format(".{}.tmp-{:08x}", file.filename().string(), rd());
}

void write_plain(const fs::path& tmp, std::string_view content) {
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(format_location(tmp, 0, fmt::format("cannot create ({})", std::strerror(errno))));
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.flush();
  if (!out) throw Error(format_location(tmp, 0, "write failed (disk full?)"));
}

void write_gzip(const fs::path& tmp, std::string_view content) {
  gzFile gz = gzopen(tmp.c_str(), "wb6");
  if (gz == nullptr) throw Error(format_location(tmp, 0, fmt::format("cannot create ({})", std::strerror(errno))));
  std::size_t done = 0;
  bool ok = true;
  while (ok && done < content.size()) {
    const auto chunk = static_cast<unsigned>(std::min<std::size_t>(content.size() - done, 1u << 20));
    ok = gzwrite(gz, content.data() + done, chunk) == static_cast<int>(chunk);
    done += chunk;
  }
  if (gzclose(gz) != Z_OK || !ok) throw Error(format_location(tmp, 0, "gzip write failed (disk full?)"));
}

}  // namespace

void write_text_atomic(const fs::path& file, std::string_view content) {
  if (!file.parent_path().empty()) fs::create_directories(file.parent_path());
  const fs::path tmp = temporary_sibling(file);
  try {
    if (is_gzip_name(file))
      write_gzip(tmp, content);
    else
      write_plain(tmp, content);
    fs::rename(tmp, file);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
}

void write_folder_atomic(const fs::path& folder, bool overwrite, const std::function<void(const fs::path&)>& fill) {
  if (fs::exists(folder) && !overwrite)
    throw InputError(folder, "already exists; choose a new output folder (antpose never overwrites data)");
  const fs::path parent = folder.parent_path().empty() ? fs::path(".") : folder.parent_path();
  fs::create_directories(parent);
  std::random_device rd;
  const fs::path tmp = parent / fmt::format(".{}.tmp-{:08x}", folder.filename().string(), rd());
  try {
    fs::create_directories(tmp);
    fill(tmp);
    if (fs::exists(folder)) {
      const fs::path old = parent / fmt::format(".{}.old-{:08x}", folder.filename().string(), rd());
      fs::rename(folder, old);
      fs::rename(tmp, folder);
      fs::remove_all(old);
    } else {
      fs::rename(tmp, folder);
    }
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(tmp, ignored);
    throw;
  }
}

}  // namespace antpose::io
