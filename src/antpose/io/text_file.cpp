#include "antpose/io/text_file.hpp"

#include <zlib.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <regex>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/io/file_access.hpp"

namespace antpose::io {
namespace fs = std::filesystem;

bool is_gzip_name(const fs::path& file) { return file.extension() == ".gz"; }

std::string read_text(const fs::path& file, std::uintmax_t max_bytes) {
  require_regular_file(file, max_bytes);
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
    if (out.size() > max_bytes) {  // a small gzip file can inflate without bound
      gzclose(gz);
      throw InputError(file, fmt::format("holds more than the {:.0f} MB antpose reads from one file once decompressed",
                                         max_bytes / 1e6));
    }
  }
  if (gzclose(gz) != Z_OK && is_gzip_name(file)) throw InputError(file, "corrupt or truncated gzip data");
  return out;
}

namespace {

fs::path temporary_sibling(const fs::path& file) {
  std::random_device rd;
  return file.parent_path() / fmt::format(".{}.tmp-{:08x}", file.filename().string(), rd());
}

// The path the symbolic link `p` names (relative links resolved against its folder), or nothing
// when `p` is no link or cannot be read.
std::optional<fs::path> link_target(const fs::path& p) {
  std::error_code ec;
  if (!fs::is_symlink(fs::symlink_status(p, ec))) return std::nullopt;
  const fs::path next = fs::read_symlink(p, ec);
  if (ec) return std::nullopt;
  return next.is_absolute() ? next : p.parent_path() / next;
}

// The path a chain of symbolic links ends at, so that an output written through a link replaces
// the file it names, never the link.
fs::path follow_links(const fs::path& path) {
  fs::path p = path;
  for (int hops = 0; const auto next = link_target(p); ++hops) {
    if (hops == 40) throw OutputError(path, "is a loop of symbolic links");
    p = *next;
  }
  return p;
}

// The descriptor a path such as /dev/stdout or /dev/fd/3 names (through /proc/self/fd/N). Such
// an output goes to the open descriptor itself: a shell's `> file` behind it keeps its offset,
// and a file behind it is never replaced by a new one.
std::optional<int> descriptor_named(const fs::path& path) {
  static const std::regex kDescriptor("/(dev|proc/self)/fd/([0-9]{1,9})");
  std::optional<fs::path> p = path;
  for (int hops = 0; p && hops <= 40; ++hops, p = link_target(*p)) {
    std::smatch m;
    const std::string text = p->lexically_normal().string();
    if (std::regex_match(text, m, kDescriptor)) return std::stoi(m[2].str());
  }
  return std::nullopt;
}

std::string gzip_bytes(std::string_view content) {
  if (content.size() > std::numeric_limits<uInt>::max()) throw Error("zlib: more than 4 GB to compress in one call");
  z_stream z{};
  if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) throw Error("zlib: deflateInit2 failed");
  std::string out(deflateBound(&z, static_cast<uLong>(content.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(content.data()));
  z.avail_in = static_cast<uInt>(content.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int status = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (status != Z_STREAM_END) throw Error("zlib: deflate did not finish");
  return out;
}

}  // namespace

void write_descriptor(int fd, std::string_view bytes, const fs::path& shown) {
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw OutputError(shown, fmt::format("cannot write ({})", std::strerror(n < 0 ? errno : EIO)));
    done += static_cast<std::size_t>(n);
  }
}

namespace {

// A regular file (or none yet): a complete temporary sibling renamed over it, with its permissions.
void replace_atomically(const fs::path& target, std::string_view bytes, const fs::path& shown) {
  std::error_code ec;
  if (!target.parent_path().empty()) fs::create_directories(target.parent_path(), ec);
  if (ec) throw OutputError(shown, fmt::format("cannot create its folder ({})", ec.message()));
  const fs::path tmp = temporary_sibling(target);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw OutputError(shown, fmt::format("cannot create a file in its folder ({})", std::strerror(errno)));
  try {
    try {
      write_descriptor(fd, bytes, shown);
    } catch (...) {
      ::close(fd);
      throw;
    }
    if (::close(fd) != 0) throw OutputError(shown, fmt::format("cannot write ({})", std::strerror(errno)));
    const fs::file_status old = fs::status(target, ec);
    if (!ec && fs::is_regular_file(old)) fs::permissions(tmp, old.permissions(), ec);
    fs::rename(tmp, target, ec);
    if (ec) throw OutputError(shown, fmt::format("cannot replace ({})", ec.message()));
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

// A character device or FIFO (a terminal, /dev/null, a pipe): written in place, never replaced.
void write_through(const fs::path& target, std::string_view bytes, const fs::path& shown) {
  const int fd = ::open(target.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw OutputError(shown, fmt::format("cannot open for writing ({})", std::strerror(errno)));
  try {
    write_descriptor(fd, bytes, shown);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

}  // namespace

void write_text_atomic(const fs::path& file, std::string_view content) {
  const std::string gz = is_gzip_name(file) ? gzip_bytes(content) : std::string();
  const std::string_view bytes = is_gzip_name(file) ? std::string_view(gz) : content;
  if (const auto fd = descriptor_named(file)) {
    std::fflush(nullptr);  // what the program printed to the descriptor through stdio comes first
    return write_descriptor(*fd, bytes, file);
  }
  // The kernel follows the links to tell the kind (a link's text may be no path: "pipe:[…]").
  switch (const FileKind kind = file_kind(file)) {
    case FileKind::kRegular:
      return replace_atomically(fs::canonical(file), bytes, file);
    case FileKind::kMissing:
      return replace_atomically(follow_links(file), bytes, file);  // a dangling link's target
    case FileKind::kCharacterDevice:
    case FileKind::kFifo:
      return write_through(file, bytes, file);
    case FileKind::kDirectory:
      throw OutputError(file, "is a folder; give a file name for the output");
    case FileKind::kOther:
      throw OutputError(
          file, fmt::format("is {}; antpose writes to regular files, character devices and FIFOs", describe(kind)));
  }
}

void write_folder_atomic(const fs::path& requested, bool overwrite, const std::function<void(const fs::path&)>& fill) {
  const FileKind kind = file_kind(requested);
  if (kind != FileKind::kMissing && kind != FileKind::kDirectory)
    throw OutputError(requested, fmt::format("is {}, expected a folder", describe(kind)));
  const fs::path folder = kind == FileKind::kDirectory ? fs::canonical(requested) : follow_links(requested);
  if (fs::exists(folder) && !overwrite)
    throw InputError(requested, "already exists; choose a new output folder (antpose never overwrites data)");
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
