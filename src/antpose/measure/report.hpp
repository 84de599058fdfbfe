// The report folder of `antpose measure --report DIR`: what an RF engineer looks at to trust (or
// not) a non-contact measurement.
//   index.html            the numbers per antenna, warnings, and two SVG plots: the plan view of
//                         each antenna (reconstructed points, registered model, boresight, north)
//                         and each photo's board heading against the median (disturbance shows)
//   overlay_NN.jpg        every photo with a board pose, the registered model's box and
//                         boresight drawn over it (and the ROI where one was marked)
//   antenna_K_points.ply  the reconstructed region, board frame, metres
//   antenna_K_model.ply   the registered model's surface samples, board frame
//   result.json           to_json(result)
// The folder is written next to its destination and renamed into place, so a failed report never
// leaves half a folder, and an existing folder is only replaced when `overwrite`.
#pragma once

#include <filesystem>

#include "antpose/measure/non_contact.hpp"
#include "antpose/store/provenance.hpp"

namespace antpose::measure {

/// The report folder: index.html (the table, the σ budget, warnings, plan views, overlays, what
/// produced it), result.json with `provenance`, the overlays and the PLY clouds. InputError when
/// `folder` exists, is not empty and `overwrite` is false.
void write_report(const std::filesystem::path& folder, const Capture& capture, const NonContactSetup& setup,
                  const NonContactResult& result, const store::Provenance& provenance, bool overwrite);

}  // namespace antpose::measure
