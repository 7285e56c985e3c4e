#include "lidarshop/pointset/site_registration.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// Every `stride`-th point (with its normal) of `cloud`: a regular subsample over the grid's row-major order.
PointCloud EveryNth(const PointCloud& cloud, int64_t max_points) {
  const int64_t n = static_cast<int64_t>(cloud.size());
  const int64_t stride = std::max<int64_t>(1, (n + max_points - 1) / max_points);
  PointCloud out;
  for (int64_t i = 0; i < n; i += stride) {
    out.points.push_back(cloud.points[i]);
    if (cloud.normals.size() == cloud.size()) out.normals.push_back(cloud.normals[i]);
  }
  return out;
}

// `cloud` (scanner frame) moved by local_from_scanner, normals turned with it.
PointCloud Moved(const PointCloud& cloud, const Eigen::Matrix4d& local_from_scanner) {
  const Eigen::Matrix3d rotation = local_from_scanner.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = local_from_scanner.topRightCorner<3, 1>();
  PointCloud out;
  out.points.resize(cloud.size());
  out.normals.resize(cloud.normals.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    out.points[i] = (rotation * cloud.points[i].cast<double>() + translation).cast<float>();
    if (i < cloud.normals.size()) out.normals[i] = (rotation * cloud.normals[i].cast<double>()).cast<float>();
  }
  return out;
}

double RotationAngleRad(const Eigen::Matrix3d& rotation) {
  return std::acos(std::clamp((rotation.trace() - 1.0) / 2.0, -1.0, 1.0));
}

Eigen::Matrix4d Inverse(const Eigen::Matrix4d& pose) {
  Eigen::Matrix4d out = Eigen::Matrix4d::Identity();
  out.topLeftCorner<3, 3>() = pose.topLeftCorner<3, 3>().transpose();
  out.topRightCorner<3, 1>() = -out.topLeftCorner<3, 3>() * pose.topRightCorner<3, 1>();
  return out;
}

// [rotation vector · scale, translation] of a rigid transform.
Vector6d Log(const Eigen::Matrix4d& pose, double rotation_scale_m) {
  const Eigen::AngleAxisd angle_axis(Eigen::Matrix3d(pose.topLeftCorner<3, 3>()));
  Vector6d out;
  out.head<3>() = angle_axis.angle() * angle_axis.axis() * rotation_scale_m;
  out.tail<3>() = pose.topRightCorner<3, 1>();
  return out;
}

// exp(δ) · pose with δ = [rotation vector (radians), translation (metres)], a left update in the local frame.
Eigen::Matrix4d Perturbed(const Eigen::Matrix4d& pose, const Vector6d& delta) {
  Eigen::Matrix4d update = Eigen::Matrix4d::Identity();
  const double angle = delta.head<3>().norm();
  if (angle > 0) update.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, delta.head<3>() / angle).matrix();
  update.topRightCorner<3, 1>() = delta.tail<3>();
  return update * pose;
}

Vector6d EdgeResidual(const Eigen::Matrix4d& a_from_b_measured, const Eigen::Matrix4d& pose_a,
                      const Eigen::Matrix4d& pose_b, double rotation_scale_m) {
  return Log(Inverse(a_from_b_measured) * Inverse(pose_a) * pose_b, rotation_scale_m);
}

// Share of `samples` within `distance` of `tree`'s points.
double ShareNear(const PointKdTree& tree, const std::vector<Eigen::Vector3f>& samples, float distance) {
  if (samples.empty()) return 0.0;
  int64_t near = 0;
  for (const Eigen::Vector3f& p : samples) near += tree.NearestWithin(p, distance).found();
  return static_cast<double>(near) / static_cast<double>(samples.size());
}

}  // namespace

void SiteRegistrationOptions::Check() const { Validate(*this); }

int OptimizePoseGraph(std::vector<Eigen::Matrix4d>* poses, std::vector<SitePair>* pairs, int fixed,
                      const SiteRegistrationOptions& options) {
  const int n = static_cast<int>(poses->size());
  // Unknowns: 6 per station but the fixed one.
  std::vector<int> column(n, -1);
  int unknowns = 0;
  for (int k = 0; k < n; ++k) {
    if (k != fixed) column[k] = 6 * (unknowns++);
  }
  const int size = 6 * unknowns;
  const double scale = options.rotation_scale_m;
  int iteration = 0;
  for (; iteration < options.graph_iterations && size > 0; ++iteration) {
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(size);
    for (const SitePair& pair : *pairs) {
      if (!pair.in_graph) continue;
      const Eigen::Matrix4d& pose_a = (*poses)[pair.a];
      const Eigen::Matrix4d& pose_b = (*poses)[pair.b];
      const Vector6d residual = EdgeResidual(pair.a_from_b_measured, pose_a, pose_b, scale);
      // Central differences: 12 columns of a 6 x 12 Jacobian (the residual is smooth and cheap).
      Eigen::Matrix<double, 6, 12> jacobian;
      constexpr double kStep = 1e-6;
      for (int j = 0; j < 12; ++j) {
        Vector6d delta = Vector6d::Zero();
        delta[j % 6] = kStep;
        const bool on_a = j < 6;
        const Vector6d plus = EdgeResidual(pair.a_from_b_measured, on_a ? Perturbed(pose_a, delta) : pose_a,
                                           on_a ? pose_b : Perturbed(pose_b, delta), scale);
        const Vector6d minus = EdgeResidual(pair.a_from_b_measured, on_a ? Perturbed(pose_a, -delta) : pose_a,
                                            on_a ? pose_b : Perturbed(pose_b, -delta), scale);
        jacobian.col(j) = (plus - minus) / (2 * kStep);
      }
      const int ends[2] = {pair.a, pair.b};
      for (int u = 0; u < 2; ++u) {
        if (column[ends[u]] < 0) continue;
        const auto ju = jacobian.middleCols<6>(6 * u);
        gradient.segment<6>(column[ends[u]]) += ju.transpose() * residual;
        for (int v = 0; v < 2; ++v) {
          if (column[ends[v]] < 0) continue;
          const Eigen::Matrix<double, 6, 6> block = ju.transpose() * jacobian.middleCols<6>(6 * v);
          for (int r = 0; r < 6; ++r)
            for (int c = 0; c < 6; ++c)
              triplets.emplace_back(column[ends[u]] + r, column[ends[v]] + c, block(r, c));
        }
      }
    }
    // A tiny damping keeps the system positive definite for a station whose pairs constrain it weakly.
    for (int i = 0; i < size; ++i) triplets.emplace_back(i, i, 1e-9);
    Eigen::SparseMatrix<double> hessian(size, size);
    hessian.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(hessian);
    if (solver.info() != Eigen::Success) throw InputError("register: the pose graph is singular");
    const Eigen::VectorXd step = solver.solve(-gradient);
    for (int k = 0; k < n; ++k) {
      if (column[k] >= 0) (*poses)[k] = Perturbed((*poses)[k], step.segment<6>(column[k]));
    }
    if (step.lpNorm<Eigen::Infinity>() < 1e-10) {
      ++iteration;
      break;
    }
  }
  for (SitePair& pair : *pairs) {
    const Eigen::Matrix4d error =
        Inverse(pair.a_from_b_measured) * Inverse((*poses)[pair.a]) * (*poses)[pair.b];
    pair.graph_translation_m = error.topRightCorner<3, 1>().norm();
    pair.graph_rotation_deg = RotationAngleRad(error.topLeftCorner<3, 3>()) * 180.0 / M_PI;
  }
  return iteration;
}

SiteRegistration RegisterSite(const std::vector<Scan>& stations, int fixed, const IcpOptions& icp,
                              const SiteRegistrationOptions& options) {
  options.Check();
  icp.Check();
  const int n = static_cast<int>(stations.size());
  CheckOption(n >= 2, fmt::format("register: a site needs 2 stations or more, got {}", n));
  CheckOption(fixed >= 0 && fixed < n, fmt::format("register: fixed station {} of {}", fixed, n));
  SiteRegistration out;
  Timer timer;
  // Local frame: centred on the fixed scanner. Poses below are local_from_scanner.
  Eigen::Matrix4d local_from_world = Eigen::Matrix4d::Identity();
  local_from_world.topRightCorner<3, 1>() = -stations[fixed].world_from_scanner.topRightCorner<3, 1>();
  std::vector<Eigen::Matrix4d> poses(n);
  std::vector<PointCloud> fixed_clouds(n), moving_clouds(n);
  for (int k = 0; k < n; ++k) {
    poses[k] = local_from_world * stations[k].world_from_scanner;
    const Scan& scan = stations[k];
    // Grid normals (facing the scanner) where the scan has none: point-to-plane needs the fixed cloud's.
    const PointCloud cloud =
        ToPointCloud(scan.normal.empty() ? WithGridNormals(scan, NormalOptions{}) : scan);
    if (cloud.size() < 100) {
      throw InputError(fmt::format("register: station {} ('{}') has {} points, too few to register", k,
                                   scan.name, cloud.size()));
    }
    fixed_clouds[k] = EveryNth(cloud, options.max_fixed_points);
    moving_clouds[k] = EveryNth(cloud, options.max_moving_points);
  }

  // 1. Overlap at the poses given.
  {
    std::vector<PointKdTree> trees;
    std::vector<std::vector<Eigen::Vector3f>> samples(n);
    for (int k = 0; k < n; ++k) {
      const PointCloud moved = Moved(moving_clouds[k], poses[k]);
      trees.emplace_back(moved.points);
      for (size_t i = 0; i < moved.size(); i += 10) samples[k].push_back(moved.points[i]);
    }
    std::vector<std::pair<int, int>> candidates;
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b) candidates.emplace_back(a, b);
    std::vector<double> overlap(candidates.size());
    const float distance = static_cast<float>(options.overlap_distance_m);
    ParallelFor(static_cast<int64_t>(candidates.size()), [&](int64_t i) {
      const auto [a, b] = candidates[i];
      overlap[i] =
          std::max(ShareNear(trees[a], samples[b], distance), ShareNear(trees[b], samples[a], distance));
    });
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (overlap[i] < options.min_overlap) continue;
      SitePair pair;
      pair.a = candidates[i].first;
      pair.b = candidates[i].second;
      pair.overlap = overlap[i];
      out.pairs.push_back(pair);
    }
    for (int k = 0; k < n; ++k) {
      if (std::none_of(out.pairs.begin(), out.pairs.end(),
                       [&](const SitePair& p) { return p.a == k || p.b == k; })) {
        throw InputError(
            fmt::format("register: station {} ('{}') overlaps no other station (less than {} of "
                        "its points within {} m of another's at the poses given)",
                        k, stations[k].name, options.min_overlap, options.overlap_distance_m));
      }
    }
  }
  out.seconds_overlap = timer.Seconds();

  // 2. Coarse pass: a spanning tree grown from the fixed station, largest overlap first.
  timer.Restart();
  {
    IcpOptions coarse = icp;
    coarse.max_correspondence_m = std::max(icp.max_correspondence_m, options.coarse_correspondence_m);
    std::vector<bool> placed(n, false);
    placed[fixed] = true;
    for (int placed_count = 1; placed_count < n; ++placed_count) {
      const SitePair* best = nullptr;
      for (const SitePair& pair : out.pairs) {
        if (placed[pair.a] == placed[pair.b]) continue;
        if (best == nullptr || pair.overlap > best->overlap) best = &pair;
      }
      if (best == nullptr) {
        throw InputError(
            "register: the stations do not form one connected site (some overlap none of the "
            "others reachable from the fixed one)");
      }
      const int parent = placed[best->a] ? best->a : best->b;
      const int child = placed[best->a] ? best->b : best->a;
      const IcpResult result =
          IcpPointToPlane(Moved(fixed_clouds[parent], poses[parent]),
                          Moved(moving_clouds[child], poses[child]), Eigen::Matrix4d::Identity(), coarse);
      poses[child] = result.fixed_from_moving * poses[child];
      placed[child] = true;
    }
  }
  out.seconds_coarse = timer.Seconds();

  // 3. Fine pass: every overlapping pair from the coarse poses.
  timer.Restart();
  for (SitePair& pair : out.pairs) {
    const Timer pair_timer;
    try {
      pair.icp =
          IcpPointToPlane(Moved(fixed_clouds[pair.a], poses[pair.a]),
                          Moved(moving_clouds[pair.b], poses[pair.b]), Eigen::Matrix4d::Identity(), icp);
      pair.a_from_b_measured = Inverse(poses[pair.a]) * pair.icp.fixed_from_moving * poses[pair.b];
      pair.in_graph = pair.icp.fitness >= options.min_fitness;
    } catch (const InputError&) {
      pair.in_graph = false;  // too few correspondences after the coarse pass: not a usable pair
    }
    pair.seconds = pair_timer.Seconds();
  }
  out.seconds_fine = timer.Seconds();

  // 4. Pose graph.
  timer.Restart();
  out.graph_iterations = OptimizePoseGraph(&poses, &out.pairs, fixed, options);
  out.seconds_graph = timer.Seconds();

  const Eigen::Matrix4d world_from_local = Inverse(local_from_world);
  out.stations.resize(n);
  for (int k = 0; k < n; ++k) {
    SiteStation& station = out.stations[k];
    station.world_from_scanner = k == fixed ? stations[k].world_from_scanner : world_from_local * poses[k];
    const Eigen::Matrix4d& before = stations[k].world_from_scanner;
    station.moved_m =
        (station.world_from_scanner.topRightCorner<3, 1>() - before.topRightCorner<3, 1>()).norm();
    station.turned_deg = RotationAngleRad(station.world_from_scanner.topLeftCorner<3, 3>() *
                                          before.topLeftCorner<3, 3>().transpose()) *
                         180.0 / M_PI;
    double sum_sq = 0;
    for (const SitePair& pair : out.pairs) {
      if (!pair.in_graph || (pair.a != k && pair.b != k)) continue;
      ++station.pairs;
      sum_sq += pair.icp.rms_m * pair.icp.rms_m;
      station.graph_translation_m = std::max(station.graph_translation_m, pair.graph_translation_m);
      station.graph_rotation_deg = std::max(station.graph_rotation_deg, pair.graph_rotation_deg);
    }
    station.rms_m = station.pairs > 0 ? std::sqrt(sum_sq / station.pairs) : 0.0;
  }
  return out;
}

SiteRegistrationSummary SummarizeSiteRegistration(const SiteRegistration& registration, int fixed) {
  SiteRegistrationSummary summary;
  for (size_t k = 0; k < registration.stations.size(); ++k) {
    SiteStationSummary& station = summary.stations.emplace_back();
    station.index = static_cast<int>(k);
    station.fixed = static_cast<int>(k) == fixed;
    station.registration = registration.stations[k];
  }
  summary.pairs = registration.pairs;
  summary.graph_iterations = registration.graph_iterations;
  summary.seconds.overlap = registration.seconds_overlap;
  summary.seconds.coarse = registration.seconds_coarse;
  summary.seconds.fine = registration.seconds_fine;
  summary.seconds.graph = registration.seconds_graph;
  return summary;
}

}  // namespace lidarshop
