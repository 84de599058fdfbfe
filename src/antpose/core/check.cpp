#include "antpose/core/check.hpp"

#include <stdexcept>

namespace antpose {

OptionProblems& OptionProblems::require(bool ok, std::string_view field, std::string_view expected) {
  if (!ok) problems_.push_back(std::string(field) + ": " + std::string(expected));
  return *this;
}

OptionProblems& OptionProblems::nest(std::string_view prefix, const OptionProblems& inner) {
  for (const auto& p : inner.problems_) problems_.push_back(std::string(prefix) + "." + p);
  return *this;
}

std::string OptionProblems::message() const {
  std::string out;
  for (const auto& p : problems_) out += (out.empty() ? "" : "; ") + p;
  return out;
}

void throw_unless_ok(const OptionProblems& problems, std::string_view what) {
  if (!problems.ok()) throw std::invalid_argument(std::string(what) + ": " + problems.message());
}

}  // namespace antpose
