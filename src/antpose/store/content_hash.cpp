#include "antpose/store/content_hash.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <limits>
#include <memory>

#include <fmt/format.h>
#include <openssl/evp.h>

#include "antpose/core/error.hpp"
#include "antpose/io/file_access.hpp"

namespace antpose::store {
namespace fs = std::filesystem;

namespace {

std::string hex_digits(const unsigned char* digest, unsigned int length) {
  std::string out;
  for (unsigned int i = 0; i < length; ++i) out += fmt::format("{:02x}", digest[i]);
  return out;
}

}  // namespace

std::string sha256_file(const fs::path& file) {
  io::require_regular_file(file, std::numeric_limits<std::uintmax_t>::max());
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open the file to hash it");
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) throw Error("OpenSSL: cannot start SHA-256");
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    if (in.gcount() > 0) EVP_DigestUpdate(ctx.get(), buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(file, "read error while hashing the file");
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx.get(), digest, &length);
  return hex_digits(digest, length);
}

std::string sha256_bytes(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1)
    throw Error("OpenSSL: SHA-256 failed");
  return hex_digits(digest, length);
}

std::vector<InputFile> hash_inputs(const fs::path& path) {
  std::vector<InputFile> files;
  if (fs::is_regular_file(path)) {
    files.push_back({path.generic_string(), sha256_file(path), fs::file_size(path)});
    return files;
  }
  if (!fs::is_directory(path)) throw InputError(path, "input to hash does not exist");
  std::vector<fs::path> paths;
  for (const auto& e : fs::recursive_directory_iterator(path))
    if (e.is_regular_file()) paths.push_back(e.path());
  std::sort(paths.begin(), paths.end());
  for (const auto& p : paths) files.push_back({p.generic_string(), sha256_file(p), fs::file_size(p)});
  return files;
}

nlohmann::json to_json(const std::vector<InputFile>& inputs) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& f : inputs) j.push_back({{"path", f.path}, {"sha256", f.sha256}, {"size_bytes", f.size}});
  return j;
}

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return fmt::format("{}.{:03d}Z", text, static_cast<int>(ms));
}

std::string content_digest(const fs::path& path) {
  if (!fs::is_directory(path)) return sha256_file(path);
  std::string lines;
  for (const auto& f : hash_inputs(path))
    lines += fmt::format("{} {}\n", fs::path(f.path).lexically_relative(path).generic_string(), f.sha256);
  return sha256_bytes(lines);
}

}  // namespace antpose::store
