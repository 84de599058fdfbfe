#include "antpose/core/error.hpp"

#include <fmt/format.h>

namespace antpose {

std::string format_location(const std::filesystem::path& file, std::size_t line, const std::string& message) {
  if (file.empty()) return message;
  if (line == 0) return fmt::format("{}: {}", file.string(), message);
  return fmt::format("{}:{}: {}", file.string(), line, message);
}

InputError::InputError(std::filesystem::path file, std::size_t line, const std::string& message)
    : Error(format_location(file, line, message)), file_(std::move(file)), line_(line), detail_(message) {}

std::string Warning::to_string() const { return format_location(file, line, message); }

void Diagnostics::warn(std::filesystem::path file, std::size_t line, std::string message) {
  warnings_.push_back(Warning{std::move(file), line, std::move(message)});
}

bool Diagnostics::mentions(const std::string& needle) const {
  for (const auto& w : warnings_)
    if (w.message.find(needle) != std::string::npos) return true;
  return false;
}

}  // namespace antpose
