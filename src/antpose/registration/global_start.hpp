// Registering an antenna model without a good guess. Local ICP settles in mirror poses from 30°
// away, and a panel is nearly a symmetric box. So hypotheses are enumerated with a gravity prior:
// panels hang almost upright (downtilt ≤ ~15°, roll ≤ a few degrees), so the model's long axis
// z_a is put along the scene's up direction, tilted by each of `downtilt_deg`, and turned about it
// on a yaw grid; its centre is put at the scene's centroid and, with `split_starts`, at the
// centroids of the scene's two halves split there across its largest horizontal spread: a region
// holding a mast beside the panel (a rooftop pipe 0.4 m away with as many points as the radome)
// puts the centroid between the two, beyond the coarse ICP's reach of either. Each hypothesis is
// refined by ICP on voxel-downsampled clouds (scene → model:
// every scene point has a counterpart on the complete model, not the reverse) and scored; the
// best one and its best rival facing the other way are then refined on the full clouds.
//
// Score of a hypothesis (lower is better), two parts:
//   - residual: mean over scene points of min(d², τ²)/τ², d the distance to the model;
//   - visibility (when the camera viewpoints are known): the fraction of model samples facing a
//     viewpoint that have no scene point within τ. A flipped model shows surface towards the
//     cameras (e.g. the bracket of the back plate) where the reconstruction saw none.
// Front/back check: the best hypothesis whose boresight points more than 90° away from the
// winner's is the rival. Their score difference is the evidence: e.g. 0.05 means 5 % more of the
// camera-facing model surface lacks scene support (or the equivalent in residuals). When it is
// below `ambiguity_margin` the result is flagged ambiguous (say so rather than report a
// confident azimuth). A ratio would not do: the winner's own score is set by the sampling.
#pragma once

#include <vector>

#include "antpose/registration/icp.hpp"

namespace antpose::registration {

struct GlobalStartOptions {
  double yaw_step_deg = 15.0;
  double coarse_voxel_m = 0.02;  // hypothesis search resolution
  // The ICPs of every start move at most this many of the scene's voxel points, spread evenly
  // (Rusinkiewicz & Levoy 2001: sampling the source costs ICP little of its reach); the score
  // weighs them all.
  std::size_t coarse_max_points = 2000;
  std::vector<double> downtilt_deg = {0.0, 10.0};
  bool split_starts = true;  // centres at the two halves' centroids too (see the file comment)
  IcpOptions coarse = [] {
    IcpOptions o;
    o.method = IcpMethod::kPointToPlane;
    o.max_correspondence_distance_m = 0.15;
    o.max_iterations = 30;
    o.transformation_epsilon = 1e-7;
    return o;
  }();
  IcpOptions fine = [] {
    IcpOptions o;
    o.method = IcpMethod::kPointToPlane;
    o.max_correspondence_distance_m = 0.03;
    o.max_iterations = 50;
    o.kernel = RobustKernel::kHuber;
    o.kernel_scale = 0.005;
    return o;
  }();
  double truncation_m = 0.02;  // τ
  double ambiguity_margin = 0.03;
  std::vector<Vec3> viewpoints_scene;  // camera centres in the scene frame (optional)
};

struct Hypothesis {
  double yaw_rad = 0.0, downtilt_rad = 0.0;  // of the start
  Vec3 centre_start_scene = Vec3::Zero();    // where the model's centre started
  Iso3 T_model_scene = Iso3::Identity();     // after refinement
  double residual = 0.0, unseen = 0.0;       // the two score parts
  double score() const { return residual + unseen; }
};

struct GlobalStartResult {
  IcpResult fit;                       // the winner, refined with the fine options on the full clouds
  Hypothesis winner, rival;            // full-resolution scores; rival.score() = ∞ without one
  std::vector<Hypothesis> hypotheses;  // all, coarse scores, best first
  double front_back_margin = 0.0;      // rival score − winner score (∞ without a rival)
  bool front_back_ambiguous = false;
};

/// `scene` (e.g. reconstructed points, board frame) and `model` (antenna frame, normals outward,
/// prepared for options.fine.method), `up_scene` the unit up direction in the scene frame.
/// std::invalid_argument for an empty cloud, a model without normals or a zero up vector.
GlobalStartResult global_align(const PreparedCloud& scene, const PreparedCloud& model, const Vec3& up_scene,
                               const GlobalStartOptions& options);

/// The cloud reduced to one point per occupied voxel (the centroid, with the mean normal).
PointCloud voxel_downsample(const PointCloud& cloud, double voxel_m);

}  // namespace antpose::registration
