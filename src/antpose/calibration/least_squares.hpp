// Internal: the one way the calibration fits run Ceres (dense problems of a few parameters).
#pragma once

#include <ceres/ceres.h>

namespace antpose::calibration {

/// Levenberg–Marquardt with a dense QR solver, silent, stopping at `tolerance` relative change
/// of cost and parameters.
inline ceres::Solver::Summary solve_levenberg_marquardt(ceres::Problem& problem, int max_iterations, double tolerance) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = tolerance;
  options.parameter_tolerance = tolerance;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return summary;
}

}  // namespace antpose::calibration
