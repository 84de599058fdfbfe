// Helpers of the end-to-end acceptance tests: running the command line as a user does, and
// reading the rotations it writes.
#pragma once

#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "antpose/geometry/rotation.hpp"
#include "support/test_support.hpp"

namespace antpose::test {

/// Runs `antpose ARGS`; a non-zero status fails the test with the command and its output.
inline void run(const std::string& args) {
  const auto r = run_cli(args);
  ASSERT_EQ(r.status, 0) << args << "\n" << r.err << r.out;
}

/// A 3 × 3 matrix in JSON, row by row ([[r0], [r1], [r2]]), as io::matrix_rows_json writes it.
/// (YAML has its validating reader in the library: io::yaml_mat3.)
inline Mat3 json_mat3(const nlohmann::json& rows) {
  Mat3 R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = rows.at(r).at(c).get<double>();
  return R;
}

}  // namespace antpose::test
