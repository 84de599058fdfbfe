// Options that check themselves (COLMAP's Options::Check, Ceres's Options::IsValid): before a
// stage runs, its options say what is wrong with them, naming the field and what it must be.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace antpose {

/// The problems found in an options struct; ok() when it is usable.
class OptionProblems {
 public:
  /// Records "field: expected" unless `ok`.
  OptionProblems& require(bool ok, std::string_view field, std::string_view expected);
  /// Takes over another struct's problems, each field prefixed with "prefix.".
  OptionProblems& nest(std::string_view prefix, const OptionProblems& inner);

  bool ok() const { return problems_.empty(); }
  const std::vector<std::string>& list() const { return problems_; }
  /// The problems joined by "; ".
  std::string message() const;

 private:
  std::vector<std::string> problems_;
};

/// std::invalid_argument("<what>: <problems>") unless `problems` is ok: options come from code,
/// so a bad one is a programming error, not bad input.
void throw_unless_ok(const OptionProblems& problems, std::string_view what);

}  // namespace antpose
