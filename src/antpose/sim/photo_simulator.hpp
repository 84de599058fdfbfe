// Photo simulator: renders what a phone camera sees of a scene made of planar textured patches
// (calibration boards, ground, walls) and triangle meshes (masts, antennas, brackets), then
// applies the optics and the sensor.
//
// Geometry (frames per docs/conventions.md): the camera is OpenCV's pinhole with the 5-coefficient
// distortion of camera::CameraIntrinsics. A pixel (u, v) (OpenCV: integer coordinates at pixel
// centres) sees along the ray R_world_camera · (x, y, 1), where (x, y) = undistort((u − cx)/fx,
// (v − cy)/fy), i.e. exactly the inverse of CameraIntrinsics::project. Every ray is intersected
// with every patch and with the triangles that may cover its pixel; the nearest hit in front of
// the camera wins (one z-buffer per sample for patches and meshes together).
//
// Meshes: the rays are fixed per renderer but distorted, so triangles are not rasterised in
// pixel space (their edges curve there); instead they are binned per photo into 16 × 16-pixel
// tiles by their bounding box in undistorted normalised coordinates (where a triangle stays a
// triangle), against each tile's precomputed normalised bounding box. A sample then tests only
// its tile's triangles, with three edge functions d·(v_i × v_j) of the ray d = (x, y, 1) from
// the camera centre, which also give its exact perspective barycentrics and depth. This beats a
// BVH here: the binning costs O(triangles × tiles they cover) once per photo, the inner loop is
// four dot products per triangle, and rays that miss every mesh (most of an outdoor photo) cost
// one tile lookup. Shared edges use the same (negated) edge vectors, so meshes are watertight.
// Smooth shading interpolates per-corner normals (smooth_corner_normals) with the barycentrics.
//
// Anti-aliasing (so that rendered boards give sub-pixel-accurate corners): each pixel averages
// S × S ray samples on a regular sub-pixel grid (a box filter over the pixel), and each sample
// reads the texture trilinearly from a mip-map pyramid of 2 × 2 box averages at the level
// where one texel covers one sample (Williams, "Pyramidal parametrics", SIGGRAPH 1983; the level
// from the geometric mean of the texture footprint). All filters are point-symmetric about the
// sample, so an X-corner's saddle point is not displaced.
//
// Shading: Lambert with an ambient term, radiance = albedo · texture · (ambient + direct ·
// max(0, n·l)) with n the patch normal on the side facing the camera and l the direction towards
// a distant light. Optics and sensor (sensor_image): motion blur of the rotation during the
// exposure (a line kernel, the image-centre flow), Gaussian defocus, photon (Poisson, as a
// Gaussian of variance = electrons) and read noise, gamma 1/2.2, 8-bit; then JPEG.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/camera/camera_model.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/model/mesh.hpp"

namespace antpose::sim {

/// A reflectance texture with its mip-map pyramid. Texel coordinates are "edge" coordinates of
/// level 0: texel (i, j) covers [i, i+1) × [j, j+1), so its centre is (i + 0.5, j + 0.5).
struct Texture {
  std::vector<cv::Mat> levels;  // CV_32FC1 reflectance in [0, 1]; levels[k] has 2^-k the size
  /// Texel coordinates of a patch point (x, y) in metres: ξ = A (x, y, 1).
  Eigen::Matrix<double, 2, 3> texel_from_patch = Eigen::Matrix<double, 2, 3>::Zero();
  bool repeat = false;  // tiles beyond its size (procedural surfaces); otherwise clamps to the edge

  /// Builds the pyramid of `reflectance` (CV_32FC1 or CV_8UC1, scaled to [0, 1]). The image is
  /// padded (edge value, or tiled when `repeat`) to a multiple of 2^(levels − 1) so that every
  /// level is an exact 2 × 2 box average of the one below. std::invalid_argument for an empty
  /// image, a repeating texture whose size is not a multiple of 2^(levels − 1), or a
  /// non-invertible texel_from_patch.
  static Texture from_image(const cv::Mat& reflectance, const Eigen::Matrix<double, 2, 3>& texel_from_patch,
                            bool repeat, int max_levels = 8);
};

/// A planar rectangle in the world with a texture. The patch frame: x, y in the plane, z = x × y
/// its normal; the rectangle is [min_xy, max_xy] in patch coordinates, metres.
struct TexturedPatch {
  std::string name;
  Mat3 R_world_patch = Mat3::Identity();
  Vec3 p_world_patch = Vec3::Zero();  // origin of the patch frame, world, m
  Eigen::Vector2d min_xy = Eigen::Vector2d::Zero(), max_xy = Eigen::Vector2d::Zero();
  std::shared_ptr<const Texture> texture;
  double albedo = 1.0;  // multiplies the texture's reflectance
};

/// A triangle mesh in the world: vertices in the object frame, placed by R_world_object,
/// p_world_object. Lambert-shaded with the interpolated corner normals (flat when empty),
/// radiance = albedo · reflectance(p_object) · (ambient + direct · max(0, n·l)).
struct MeshObject {
  std::string name;
  model::Mesh mesh;                                 // object frame, m
  std::vector<std::array<Vec3, 3>> corner_normals;  // object frame, one per triangle corner
  Mat3 R_world_object = Mat3::Identity();
  Vec3 p_world_object = Vec3::Zero();
  double albedo = 0.5;
  /// Optional reflectance multiplier at an object-frame surface point (weathering, labels);
  /// must be thread-safe (called concurrently).
  std::function<double(const Vec3& p_object)> reflectance;
  /// A closed, outward-wound mesh: faces turned away from the camera are skipped (never
  /// visible). Otherwise both sides are drawn, shaded on the side facing the camera.
  bool cull_back_faces = true;
};

/// Per-corner normals of a mesh, smoothed across edges whose dihedral angle is below
/// `crease_rad` (face normals of the triangles around each vertex weighted by their corner
/// angles; vertices at the same position are welded first), so rounded panel edges shade smoothly while box edges
/// stay sharp. Normals follow the winding (model/mesh.hpp).
std::vector<std::array<Vec3, 3>> smooth_corner_normals(const model::Mesh& mesh, double crease_rad);

/// Appends a closed part to a mesh object, its corner normals smoothed on their own (the parts
/// of one object, such as a panel and its end caps, are not smoothed into each other).
/// std::invalid_argument when the object is flat-shaded (no corner normals) but has triangles.
void append_part(MeshObject& object, const model::Mesh& part, double crease_rad);

/// What a photo shows: planar patches and meshes. Object ids (PhotoRenderer::render) number the
/// patches 0..P−1, then the meshes P..P+M−1.
struct Scene {
  std::vector<TexturedPatch> patches;
  std::vector<MeshObject> meshes;
};

/// A sky whose radiance changes from the horizon to the zenith, L = horizon + (zenith − horizon)
/// √sin(elevation) (rays below the horizon see the horizon), optionally with clouds on a layer
/// 1 km up: the sky times 2·texture at the ray's point on the layer, faded out towards the
/// horizon where the layer's texture would alias.
struct SkyDome {
  double zenith = 0.9, horizon = 0.9;
  /// A tileable texture (Texture::repeat) of mean 0.5 over the layer's metres; empty: clear.
  std::shared_ptr<const Texture> clouds;
};

/// A distant light and an ambient term (see the file comment).
struct Lighting {
  Vec3 towards_light_world = Vec3(0.3, -0.5, 0.81).normalized();  // sun in the south-east, 54° high
  double ambient = 0.6;
  double direct = 0.4;
  double sky = 0.9;               // radiance of a ray that hits no patch
  std::optional<SkyDome> dome;    // replaces the uniform `sky` when set
};

/// Radiance of the sky along a world direction (any length): `sky`, or the dome's.
double sky_radiance(const Lighting& lighting, const Vec3& direction_world);

/// Pose of the camera: R_world_camera rotates camera-frame vectors into the world; the optical
/// centre is at p_world_camera, m.
struct CameraPose {
  Mat3 R_world_camera = Mat3::Identity();
  Vec3 p_world_camera = Vec3::Zero();
};

/// Pixel of a world point seen from `pose` (CameraIntrinsics::project in the camera frame);
/// std::nullopt behind the camera.
std::optional<Vec2> project_world(const camera::CameraIntrinsics& intrinsics, const CameraPose& pose,
                                  const Vec3& p_world);

/// Renders linear radiance images of a camera. Construction undistorts every pixel centre once
/// (the ray grid and its Jacobian d(x, y)/d(u, v)), so one renderer serves many photos.
class PhotoRenderer {
 public:
  /// std::invalid_argument for unusable intrinsics (invalid_reason) or supersampling outside 1..8.
  explicit PhotoRenderer(const camera::CameraIntrinsics& intrinsics, int supersampling = 3);

  /// CV_32FC1 radiance (height × width), 1.0 = a white surface fully lit with ambient + direct = 1.
  /// Parallel over rows (cv::parallel_for_).
  cv::Mat render(const std::vector<TexturedPatch>& patches, const CameraPose& pose, const Lighting& lighting) const;
  /// The same for patches and meshes; `object_ids` (optional) receives CV_32SC1 the object id
  /// (Scene) hit by each pixel's central sample, −1 for the sky. std::invalid_argument for a
  /// patch without a texture or a mesh triangle indexing outside its vertices.
  cv::Mat render(const Scene& scene, const CameraPose& pose, const Lighting& lighting,
                 cv::Mat* object_ids = nullptr) const;

  const camera::CameraIntrinsics& intrinsics() const { return intrinsics_; }
  int supersampling() const { return supersampling_; }

 private:
  camera::CameraIntrinsics intrinsics_;
  int supersampling_;
  cv::Mat xy_;                      // CV_32FC2: undistorted normalised (x, y) of each pixel centre
  cv::Mat jacobian_;                // CV_32FC4: (dx/du, dx/dv, dy/du, dy/dv)
  static constexpr int kTile = 16;  // px, side of the mesh binning tiles
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<std::array<float, 4>> tile_box_;  // per tile: normalised x0, x1, y0, y1 of its samples
};

/// Optics and sensor of the simulated phone camera.
struct SensorModel {
  double exposure_s = 0.002;    // motion blur length = image flow × exposure
  double blur_sigma_px = 0.6;   // Gaussian defocus / lens PSF, px (0: none)
  double gain = 0.85;           // fraction of the full well reached by radiance 1.0
  double full_well_e = 6000.0;  // electrons (a 1.4 µm phone pixel)
  double read_noise_e = 3.0;    // electrons rms
  double noise_scale = 1.0;     // multiplies photon and read noise; 0: noise-free
  double gamma = 2.2;           // output encoding: value = linear^(1/gamma)
  int jpeg_quality = 92;        // 1..100
};

/// Blurs a radiance image along the image motion of a rotation at `omega_camera` (rad/s, camera
/// frame) during `exposure_s`: the flow of the principal ray, (−fx ω_y, fy ω_x) px/s, as a
/// centred line kernel (so the image shows the pose at the middle of the exposure). Rotation
/// about the optical axis and translation are neglected (a few pixels of roll smear at the
/// corners at most for hand-held rates). Returns the input when the smear is below 0.05 px.
cv::Mat motion_blur(const cv::Mat& radiance, const camera::CameraIntrinsics& intrinsics, const Vec3& omega_camera,
                    double exposure_s);

/// Defocus, noise (seeded: deterministic) and gamma: CV_8UC1 from a CV_32FC1 radiance image.
cv::Mat sensor_image(const cv::Mat& radiance, const SensorModel& sensor, std::uint64_t noise_seed);

/// JPEG bytes of an 8-bit image at `quality` (cv::imencode).
std::string encode_jpeg(const cv::Mat& image, int quality);

}  // namespace antpose::sim
