#include "antpose/measure/registration_scene.hpp"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "antpose/camera/board_pose.hpp"
#include "antpose/model/box_file.hpp"
#include "antpose/registration/known_object_masks.hpp"

namespace antpose::measure {

std::vector<cv::Point2f> box_hull(const KnownBox& box, const camera::CameraIntrinsics& K, const Mat3& R_cb,
                                  const Vec3& t_cb) {
  std::vector<cv::Point2f> corners, hull;
  for (const Vec3& c : model::box_corners(box.size_m)) {
    const auto uv = K.project(R_cb * (box.T_board_box * c) + t_cb);
    if (!uv) return {};
    corners.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
  }
  cv::convexHull(corners, hull);
  return hull;
}

namespace {

// Adds a known object to a photo: an occluder where it is nearer the camera than the antenna,
// else its outline as edges that are not the antenna's.
void add_known(registration::SilhouetteView& v, std::vector<cv::Point2f> outline, bool in_front) {
  if (outline.size() < 3) return;
  if (in_front) {
    v.occluders.push_back(std::move(outline));
  } else {
    outline.push_back(outline.front());
    v.background_edges.push_back(std::move(outline));
  }
}

void add_mast(registration::SilhouetteView& v, const reconstruction::Mast& mast, const camera::CameraIntrinsics& K,
              const Vec3& camera_board, const Vec3& antenna_board) {
  auto lines = reconstruction::mast_outline(mast, K, v.R_camera_board, v.t_camera_board);
  if (lines[0].empty()) return;
  if (reconstruction::mast_in_front(mast, camera_board, antenna_board)) {
    auto& polygon = v.occluders.emplace_back(std::move(lines[0]));
    polygon.insert(polygon.end(), lines[1].rbegin(), lines[1].rend());
  } else {
    v.background_edges.push_back(std::move(lines[0]));
    v.background_edges.push_back(std::move(lines[1]));
  }
}

bool near_box(const KnownBox& box, const Vec3& p_board, double clearance) {
  const Vec3 q = box.T_board_box.inverse() * p_board;
  return (q.cwiseAbs().array() <= (box.size_m / 2).array() + clearance).all();
}

// Whether a region point lies on a known object: a neighbour's box or the mast.
bool known_object_at(const Vec3& p_board, const SceneObjects& o) {
  if (o.mast && reconstruction::on_mast(*o.mast, p_board, o.object_clearance_m)) return true;
  return std::any_of(o.neighbours.begin(), o.neighbours.end(),
                     [&](const KnownBox& b) { return near_box(b, p_board, o.object_clearance_m); });
}

// Where the antenna may show in a photo: the region carried there, and the rectangle's frustum
// over the depths where the model fills it, grown.
std::optional<cv::Rect> area_in(std::size_t v, const CameraPoses& poses,
                                const reconstruction::RegionReconstruction& region, std::size_t region_view,
                                const cv::Rect& roi, const SceneObjects& o) {
  Eigen::AlignedBox2d box;
  if (v < region.rois.size() && region.rois[v]) {
    const auto& r = *region.rois[v];
    box.extend(Vec2(r.x, r.y)).extend(Vec2(r.x + r.width, r.y + r.height));
  }
  if (o.antenna_depth_m) {
    const auto& K = poses.intrinsics;
    const auto& ref = poses.views[region_view];
    const auto& view = poses.views[v];
    for (const double depth : {o.antenna_depth_m->first, o.antenna_depth_m->second})
      for (const Vec2& corner : {Vec2(roi.x, roi.y), Vec2(roi.x + roi.width, roi.y), Vec2(roi.x, roi.y + roi.height),
                                 Vec2(roi.x + roi.width, roi.y + roi.height)}) {
        const Vec3 ray = K.ray(corner);
        const Vec3 p_board = ref.R_camera_board.transpose() * (ray / ray.z() * depth - ref.t_camera_board);
        if (const auto uv = K.project(view.R_camera_board * p_board + view.t_camera_board)) box.extend(*uv);
      }
  }
  if (box.isEmpty()) return std::nullopt;
  const int g = static_cast<int>(o.area_growth * box.sizes().maxCoeff() + o.area_margin_px);
  const cv::Rect area = cv::Rect(static_cast<int>(box.min().x()) - g, static_cast<int>(box.min().y()) - g,
                                 static_cast<int>(box.sizes().x()) + 2 * g, static_cast<int>(box.sizes().y()) + 2 * g) &
                        cv::Rect(0, 0, poses.intrinsics.width, poses.intrinsics.height);
  if (area.width < 16 || area.height < 16) return std::nullopt;
  return area;
}

}  // namespace

std::pair<double, double> depths_filling(const Vec3& size_m, const cv::Rect& roi, const camera::CameraIntrinsics& K) {
  // The box's largest side spans at most the rectangle's longer side less its margin: nearer than
  // that the box would overflow it; seen foreshortened it may stand nearer still.
  const double focal = 0.5 * (K.fx + K.fy);
  const double depth = focal * size_m.maxCoeff() / (std::max(roi.width, roi.height) / 1.1);
  return {0.4 * depth, 1.4 * depth};
}

std::vector<cv::Point2f> board_outline(const std::pair<Vec3, Vec3>& box, const camera::CameraIntrinsics& K,
                                       const Mat3& R_camera_board, const Vec3& t_camera_board) {
  const auto& [lo, hi] = box;
  std::vector<cv::Point2f> poly;
  for (const Vec2& c : {Vec2(lo.x(), lo.y()), Vec2(hi.x(), lo.y()), Vec2(hi.x(), hi.y()), Vec2(lo.x(), hi.y())}) {
    const auto uv = K.project(R_camera_board * Vec3(c.x(), c.y(), 0.0) + t_camera_board);
    if (!uv) return {};
    poly.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
  }
  return poly;
}

registration::AntennaScene registration_scene(const CameraPoses& poses, const Vec3& up_board,
                                              const reconstruction::RegionReconstruction& region,
                                              std::size_t region_view, const cv::Rect& roi,
                                              const SceneObjects& objects) {
  registration::AntennaScene s;
  s.intrinsics = poses.intrinsics;
  s.up_board = up_board.normalized();
  s.region_view = region_view;
  s.roi = roi;
  s.mast = objects.mast;
  for (const auto& b : objects.neighbours) s.neighbours_board.push_back({b.T_board_box, b.size_m});
  for (const Vec3& p : region.cloud_board.points)
    if (!known_object_at(p, objects)) s.points_board.points.push_back(p);
  const Vec3 centre = s.points_board.empty() ? Vec3::Zero() : Vec3(centroid(s.points_board.points));
  for (std::size_t i = 0; i < poses.views.size(); ++i) {
    const auto& pv = poses.views[i];
    const Vec3 camera = camera::camera_centre(pv.R_camera_board, pv.t_camera_board);
    s.viewpoints_board.push_back(camera);
    registration::SilhouetteView& v = s.views.emplace_back();
    v.image = pv.image, v.R_camera_board = pv.R_camera_board, v.t_camera_board = pv.t_camera_board;
    if (i < poses.edges.size()) v.edges = poses.edges[i];
    v.masks = std::make_shared<registration::KnownObjectMasks>();
    add_known(v, board_outline(objects.board_box, s.intrinsics, v.R_camera_board, v.t_camera_board), true);
    if (objects.mast) add_mast(v, *objects.mast, s.intrinsics, camera, centre);
    for (const auto& b : objects.neighbours)
      add_known(v, box_hull(b, s.intrinsics, v.R_camera_board, v.t_camera_board),
                (b.T_board_box.translation() - camera).norm() < (centre - camera).norm());
    s.areas.push_back(area_in(i, poses, region, region_view, roi, objects));
  }
  return s;
}

}  // namespace antpose::measure
