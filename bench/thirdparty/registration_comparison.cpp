// antpose's ICP against PCL's and Open3D's on the same clouds, in the same run: accuracy and
// speed as ratios. Built only when PCL and Open3D are installed (benchmark-only dependencies:
// scripts/install-bench-deps.sh); antpose itself never links them.
//
//   antpose_bench_registration [SHARED_DIR] [--json OUT] [--repeats N]
//
// Cases (identical settings for every library: max correspondence distance, 50 iterations,
// transformation ε 1e-8; Open3D stops on relative fitness/RMSE changes of 1e-6 instead):
//   bunny  bun0 → bun4 (PCL's unit test), truth = PCL's expected transform;
//   panel  a partial scan of a 1.31 × 0.30 × 0.16 m box (front and one side, 4 mm spacing, 3 mm
//          noise, ~38k points) against the complete box surface (5 mm spacing, ~52k points),
//          started 4° and 3 cm from the truth.
// The bunny's "truth" is PCL's point-to-point optimum: the other objectives have their own
// optimum on these two partial views (all three libraries agree on it).
// Times: median of N runs of the alignment alone (trees, normals and covariances built before),
// one thread for every library (PCL is single-threaded) and antpose also with all threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <open3d/Open3D.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include "antpose/model/mesh.hpp"
#include "antpose/registration/icp.hpp"

namespace {
using namespace antpose;
namespace fs = std::filesystem;

struct Case {
  std::string name;
  PointCloud source, target;
  Iso3 T_truth, T_start;
  double max_distance;
};

// Uniform samples on the surface of an axis-aligned box centred at the origin, with outward
// normals; `keep` selects faces by their normal.
PointCloud box_surface(const Vec3& size, double spacing, std::mt19937_64& rng,
                       const std::function<bool(const Vec3&)>& keep) {
  PointCloud c;
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1}) {
      Vec3 n = Vec3::Zero();
      n[axis] = sign;
      if (!keep(n)) continue;
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      const auto count = static_cast<int>(size[a] * size[b] / (spacing * spacing));
      for (int i = 0; i < count; ++i) {
        Vec3 p;
        p[axis] = 0.5 * sign * size[axis];
        p[a] = u(rng) * size[a];
        p[b] = u(rng) * size[b];
        c.points.push_back(p);
        c.normals.push_back(n);
      }
    }
  return c;
}

Iso3 pose(const Vec3& w, const Vec3& t) {
  Iso3 T = Iso3::Identity();
  T.linear() = exp_so3(w);
  T.translation() = t;
  return T;
}

std::vector<Case> make_cases(const fs::path& shared) {
  std::vector<Case> cases;
  Case bunny;
  bunny.name = "bunny";
  bunny.source = PointCloud{model::read_mesh(shared / "data/pointclouds/pcl/bun0.ply").vertices, {}};
  bunny.target = PointCloud{model::read_mesh(shared / "data/pointclouds/pcl/bun4.ply").vertices, {}};
  Eigen::Matrix4d E;
  E << 0.8806, 0.036481287330389023, -0.4724, 0.03453, -0.02354, 0.9992, 0.03326, -0.001519, 0.4732, -0.01817, 0.8808,
      0.04116, 0, 0, 0, 1;
  bunny.T_truth.matrix() = E;
  bunny.T_truth.linear() = nearest_rotation(bunny.T_truth.linear());
  bunny.T_start = Iso3::Identity();
  bunny.max_distance = 0.05;
  cases.push_back(bunny);

  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.003);
  const Vec3 size(0.30, 0.16, 1.31);
  Case panel;
  panel.name = "panel";
  panel.target = box_surface(size, 0.005, rng, [](const Vec3&) { return true; });
  const PointCloud seen = box_surface(size, 0.004, rng, [](const Vec3& n) { return n.y() > 0 || n.x() > 0; });
  panel.T_truth = pose(Vec3(0.02, -0.05, 0.9), Vec3(0.1, -0.2, 0.05));  // target ← source
  panel.source = transformed(seen, panel.T_truth.inverse());
  for (auto& p : panel.source.points) p += Vec3(noise(rng), noise(rng), noise(rng));
  panel.source.normals.clear();
  panel.T_start = pose(Vec3(0.04, 0.03, -0.05).normalized() * deg2rad(4.0), Vec3(0.02, -0.02, 0.01)) * panel.T_truth;
  panel.max_distance = 0.05;
  cases.push_back(panel);
  return cases;
}

struct Run {
  std::string library, method;
  double seconds = 0.0;
  double rotation_error_deg = 0.0, translation_error_m = 0.0;
  int threads = 1;
};

template <class F>
double median_seconds(int repeats, F&& f) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

void errors(Run& r, const Case& c, const Eigen::Matrix4d& T) {
  Iso3 X;
  X.matrix() = T;
  const Iso3 E = X * c.T_truth.inverse();
  r.rotation_error_deg = rad2deg(rotation_angle(nearest_rotation(E.linear())));
  r.translation_error_m = E.translation().norm();
}

pcl::PointCloud<pcl::PointXYZ>::Ptr to_pcl(const PointCloud& c) {
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : c.points)
    out->push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())));
  return out;
}

pcl::PointCloud<pcl::PointNormal>::Ptr to_pcl_normals(const PointCloud& c, const std::vector<Vec3>& normals) {
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>();
  for (std::size_t i = 0; i < c.size(); ++i) {
    pcl::PointNormal p;
    p.x = static_cast<float>(c.points[i].x()), p.y = static_cast<float>(c.points[i].y()),
    p.z = static_cast<float>(c.points[i].z());
    p.normal_x = static_cast<float>(normals[i].x()), p.normal_y = static_cast<float>(normals[i].y()),
    p.normal_z = static_cast<float>(normals[i].z());
    out->push_back(p);
  }
  return out;
}

open3d::geometry::PointCloud to_o3d(const PointCloud& c, const std::vector<Vec3>* normals) {
  open3d::geometry::PointCloud out;
  out.points_ = c.points;
  if (normals) out.normals_ = *normals;
  return out;
}

std::vector<Run> run_case(const Case& c, int repeats) {
  std::vector<Run> runs;
  const std::vector<std::pair<registration::IcpMethod, const char*>> methods = {
      {registration::IcpMethod::kPointToPoint, "point-to-point"},
      {registration::IcpMethod::kPointToPlane, "point-to-plane"},
      {registration::IcpMethod::kGeneralized, "generalized"}};
  const int all_threads = tbb::info::default_concurrency();
  for (const auto& [method, name] : methods) {
    registration::IcpOptions o;
    o.method = method;
    o.max_correspondence_distance_m = c.max_distance;
    // antpose: the same normals for everyone (PCA, k = 10) so only the solvers differ.
    const auto target = registration::prepare(c.target, o);
    const auto source = registration::prepare(c.source, o);
    for (int threads : {1, all_threads}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
      Run r{"antpose", name};
      r.threads = threads;
      registration::IcpResult res;
      r.seconds = median_seconds(repeats, [&] { res = registration::align(source, target, c.T_start, o); });
      errors(r, c, res.T_target_source.matrix());
      runs.push_back(r);
      if (all_threads == 1) break;
    }
    // PCL (float, single thread).
    {
      Run r{"pcl", name};
      Eigen::Matrix4f start = c.T_start.matrix().cast<float>();
      Eigen::Matrix4f T;
      if (method == registration::IcpMethod::kPointToPoint) {
        pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
        icp.setInputSource(to_pcl(c.source));
        icp.setInputTarget(to_pcl(c.target));
        icp.setMaxCorrespondenceDistance(c.max_distance);
        icp.setMaximumIterations(50);
        icp.setTransformationEpsilon(1e-8);
        pcl::PointCloud<pcl::PointXYZ> out;
        r.seconds = median_seconds(repeats, [&] { icp.align(out, start); });
        T = icp.getFinalTransformation();
      } else if (method == registration::IcpMethod::kPointToPlane) {
        pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
        icp.setInputSource(to_pcl_normals(c.source, source.cloud.has_normals()
                                                        ? source.cloud.normals
                                                        : std::vector<Vec3>(c.source.size(), Vec3::UnitZ())));
        icp.setInputTarget(to_pcl_normals(c.target, target.cloud.normals));
        icp.setMaxCorrespondenceDistance(c.max_distance);
        icp.setMaximumIterations(50);
        icp.setTransformationEpsilon(1e-8);
        pcl::PointCloud<pcl::PointNormal> out;
        r.seconds = median_seconds(repeats, [&] { icp.align(out, start); });
        T = icp.getFinalTransformation();
      } else {
        pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
        icp.setInputSource(to_pcl(c.source));
        icp.setInputTarget(to_pcl(c.target));
        icp.setMaxCorrespondenceDistance(c.max_distance);
        icp.setMaximumIterations(50);
        icp.setTransformationEpsilon(1e-8);
        pcl::PointCloud<pcl::PointXYZ> out;
        // PCL's GICP computes its covariances inside align(): included in its time.
        r.seconds = median_seconds(repeats, [&] { icp.align(out, start); });
        T = icp.getFinalTransformation();
      }
      errors(r, c, T.cast<double>());
      runs.push_back(r);
    }
    // Open3D (double, OpenMP; one thread to compare like with like).
    {
      open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
      Run r{"open3d", name};
      namespace reg = open3d::pipelines::registration;
      const auto src = to_o3d(c.source, nullptr);
      const auto dst =
          to_o3d(c.target, method == registration::IcpMethod::kPointToPoint ? nullptr : &target.cloud.normals);
      const reg::ICPConvergenceCriteria criteria(1e-6, 1e-6, 50);
      reg::RegistrationResult res;
      if (method == registration::IcpMethod::kGeneralized) {
        r.seconds = median_seconds(repeats, [&] {
          res = reg::RegistrationGeneralizedICP(src, dst, c.max_distance, c.T_start.matrix(),
                                                reg::TransformationEstimationForGeneralizedICP(), criteria);
        });
      } else if (method == registration::IcpMethod::kPointToPlane) {
        r.seconds = median_seconds(repeats, [&] {
          res = reg::RegistrationICP(src, dst, c.max_distance, c.T_start.matrix(),
                                     reg::TransformationEstimationPointToPlane(), criteria);
        });
      } else {
        r.seconds = median_seconds(repeats, [&] {
          res = reg::RegistrationICP(src, dst, c.max_distance, c.T_start.matrix(),
                                     reg::TransformationEstimationPointToPoint(), criteria);
        });
      }
      errors(r, c, res.transformation_);
      runs.push_back(r);
    }
  }
  return runs;
}

}  // namespace

int main(int argc, char** argv) {
  fs::path shared = ANTPOSE_SHARED_DIR;
  std::string json_out;
  int repeats = 9;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json" && i + 1 < argc)
      json_out = argv[++i];
    else if (a == "--repeats" && i + 1 < argc)
      repeats = std::max(1, std::atoi(argv[++i]));
    else
      shared = a;
  }
  if (!fs::exists(shared / "data/pointclouds/pcl/bun0.ply")) {
    std::fprintf(stderr, "error: %s: no data/pointclouds/pcl/bun0.ply (pass the shared folder)\n", shared.c_str());
    return 2;
  }
  // Open3D runs OpenMP loops: one thread, like PCL (set before any Open3D call).
  setenv("OMP_NUM_THREADS", "1", 0);
  nlohmann::json j;
  for (const auto& c : make_cases(shared)) {
    const auto runs = run_case(c, repeats);
    fmt::print("\n{}: {} source / {} target points, start {:.2f}° and {:.1f} mm from the truth\n", c.name,
               c.source.size(), c.target.size(), rad2deg(rotation_angle((c.T_start * c.T_truth.inverse()).linear())),
               1e3 * (c.T_start * c.T_truth.inverse()).translation().norm());
    fmt::print("{:<16} {:<8} {:>7} {:>11} {:>12} {:>12} {:>14}\n", "method", "library", "threads", "time ms",
               "rot err °", "trans err mm", "time / antpose");
    for (const auto& r : runs) {
      const auto base = std::find_if(runs.begin(), runs.end(), [&](const Run& b) {
        return b.library == "antpose" && b.method == r.method && b.threads == 1;
      });
      fmt::print("{:<16} {:<8} {:>7} {:>11.3f} {:>12.4f} {:>12.3f} {:>14.2f}\n", r.method, r.library, r.threads,
                 1e3 * r.seconds, r.rotation_error_deg, 1e3 * r.translation_error_m, r.seconds / base->seconds);
      j[c.name].push_back({{"library", r.library},
                           {"method", r.method},
                           {"threads", r.threads},
                           {"seconds", r.seconds},
                           {"rotation_error_deg", r.rotation_error_deg},
                           {"translation_error_m", r.translation_error_m},
                           {"time_ratio_to_antpose", r.seconds / base->seconds}});
    }
  }
  if (!json_out.empty()) std::ofstream(json_out) << j.dump(2) << "\n";
  return 0;
}
