// Helpers of the end-to-end acceptance tests: running the command line as a user does, and
// reading the rotations it and the simulator write.
#pragma once

#include <string>
#include <type_traits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "antpose/geometry/rotation.hpp"
#include "support/test_support.hpp"

namespace antpose::test {

/// Runs `antpose ARGS`; a non-zero status fails the test with the command and its output.
inline void run(const std::string& args) {
  const auto r = run_cli(args);
  ASSERT_EQ(r.status, 0) << args << "\n" << r.err << r.out;
}

/// A 3 × 3 matrix written row by row ([[r0], [r1], [r2]]) in JSON or YAML.
template <class Node>
Mat3 matrix_rows(const Node& rows) {
  Mat3 R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      if constexpr (std::is_same_v<Node, YAML::Node>)
        R(r, c) = rows[r][c].template as<double>();
      else
        R(r, c) = rows[r][c].template get<double>();
    }
  return R;
}

}  // namespace antpose::test
