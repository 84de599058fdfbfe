// Small text pieces shared by the JSON and HTML/SVG outputs of the commands.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "antpose/geometry/rotation.hpp"

namespace antpose::io {

/// A 3 × 3 matrix as JSON rows: [[r00, r01, r02], [r10, ...], [r20, ...]].
nlohmann::json matrix_rows_json(const Mat3& M);

/// Text made safe inside XML/HTML elements and attribute values (&, <, >, ").
std::string xml_escape(std::string_view text);

}  // namespace antpose::io
