// Inputs identified by content (SHA-256), and the UTC time stamps that records carry.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace antpose::store {

/// One input file, identified by content.
struct InputFile {
  std::string path;         // as given (a folder's files: folder/relative path)
  std::string sha256;       // lowercase hex
  std::uintmax_t size = 0;  // bytes
};

/// SHA-256 (FIPS 180-4, via OpenSSL EVP) of a file's bytes, lowercase hex. InputError when it is
/// not a regular file or unreadable.
std::string sha256_file(const std::filesystem::path& file);
/// SHA-256 of bytes in memory, lowercase hex.
std::string sha256_bytes(std::string_view bytes);
/// Every regular file under `path` (recursively, sorted by name), or `path` itself when it is a file.
std::vector<InputFile> hash_inputs(const std::filesystem::path& path);
nlohmann::json to_json(const std::vector<InputFile>& inputs);

/// One digest for a file or a folder: a file's SHA-256, or for a folder the SHA-256 of its files'
/// lines "relative/path sha256\n" in name order, so that renaming, changing, adding or removing
/// any file changes it and nothing else does (not the folder's own name or place).
std::string content_digest(const std::filesystem::path& path);

/// ISO 8601 UTC timestamp of now, with milliseconds.
std::string utc_now();

}  // namespace antpose::store
