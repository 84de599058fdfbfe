// Internal: the one way the calibration fits run Ceres (dense problems of a few parameters).
#pragma once

#include <Eigen/Core>
#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <vector>

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

/// 1σ of the 9 parameters of block `p` after a fit: sqrt(diag(σ̂² (JᵀJ)⁻¹)) with the residual
/// variance σ̂² = 2·cost / redundancy (Ceres' cost is ½‖r‖²). Leaves `sigma` unchanged when the
/// covariance cannot be computed.
inline void parameter_sigmas(ceres::Problem& problem, const double* p, double final_cost, double redundancy,
                             Eigen::Matrix<double, 9, 1>& sigma) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = -1;
  ceres::Covariance covariance(options);
  const std::vector<std::pair<const double*, const double*>> blocks = {{p, p}};
  if (!covariance.Compute(blocks, &problem)) return;
  double cov[81];
  covariance.GetCovarianceBlock(p, p, cov);
  const double s2 = 2.0 * final_cost / redundancy;
  for (int i = 0; i < 9; ++i) sigma[i] = std::sqrt(std::max(0.0, cov[i * 9 + i] * s2));
}

}  // namespace antpose::calibration
