#include "lidarshop/pointset/registration.h"

#include <cmath>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// Normal equations of the linearized point-to-plane error: x = (rotation vector, translation).
struct System {
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  double residual_sq = 0.0;
  double distance_sq = 0.0;  // point to point
  int64_t count = 0;
  void Add(const System& other) {
    ata += other.ata;
    atb += other.atb;
    residual_sq += other.residual_sq;
    distance_sq += other.distance_sq;
    count += other.count;
  }
};

constexpr int64_t kBlock = 4096;  // fixed blocks summed in order: the same sums whatever the thread count

}  // namespace

void IcpOptions::Check() const { Validate(*this); }

IcpResult IcpPointToPlane(const PointCloud& fixed, const PointCloud& moving,
                          const Eigen::Matrix4d& initial_fixed_from_moving, const IcpOptions& options) {
  options.Check();
  CheckCloudHasShape(fixed, "ICP (fixed cloud)");
  CheckCloudHasShape(moving, "ICP (moving cloud)");
  CheckOption(IsRigid(initial_fixed_from_moving, 1e-5), "ICP: the initial guess must be rigid");
  std::vector<Eigen::Vector3f> normals = fixed.normals;
  if (normals.size() != fixed.size()) {
    NormalOptions normal_options;
    normal_options.neighbors = options.normal_neighbors;
    // Orientation does not matter for point-to-plane; face the centroid-free origin.
    normals = EstimateNormals(fixed, normal_options).normals;
  }
  const PointKdTree tree(fixed.points);
  float max_distance = static_cast<float>(options.max_correspondence_m);
  const bool check_normals = moving.normals.size() == moving.size() && options.min_normal_cos > -1.0;
  const int64_t n = static_cast<int64_t>(moving.size());
  const int64_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<System> partial(blocks);
  IcpResult result;
  result.fixed_from_moving = initial_fixed_from_moving;
  for (result.iterations = 1; result.iterations <= options.max_iterations; ++result.iterations) {
    const Eigen::Matrix4d transform = result.fixed_from_moving;
    const Eigen::Matrix3d rotation = transform.topLeftCorner<3, 3>();
    ParallelFor(blocks, [&](int64_t block) {
      System system;
      for (int64_t i = block * kBlock; i < std::min(n, (block + 1) * kBlock); ++i) {
        const Eigen::Vector3f p = TransformPoint(transform, moving.points[i]);
        const NearestResult nearest = tree.NearestWithin(p, max_distance);
        if (!nearest.found()) continue;
        const Eigen::Vector3d normal = normals[nearest.index].cast<double>();
        if (normal.squaredNorm() < 0.5) continue;  // no normal there
        if (check_normals &&
            std::abs(normal.dot(rotation * moving.normals[i].cast<double>())) < options.min_normal_cos) {
          continue;
        }
        const Eigen::Vector3d source = p.cast<double>();
        const double residual = normal.dot(source - fixed.points[nearest.index].cast<double>());
        Eigen::Matrix<double, 6, 1> row;
        row << source.cross(normal), normal;
        system.ata.selfadjointView<Eigen::Upper>().rankUpdate(row);
        system.atb -= row * residual;
        system.residual_sq += residual * residual;
        system.distance_sq += nearest.distance_sq;
        ++system.count;
      }
      partial[block] = system;
    });
    System total;
    for (const System& s : partial) total.Add(s);
    result.correspondences = total.count;
    result.fitness = static_cast<double>(total.count) / static_cast<double>(n);
    if (total.count < 6) {
      throw InputError(fmt::format("ICP: only {} correspondences within {} m; give a closer initial guess",
                                   total.count, options.max_correspondence_m));
    }
    result.rms_m = std::sqrt(total.residual_sq / static_cast<double>(total.count));
    const double distance_rms = std::sqrt(total.distance_sq / static_cast<double>(total.count));
    const float next_distance = std::max(static_cast<float>(options.min_correspondence_m),
                                         std::min(max_distance, static_cast<float>(3.0 * distance_rms)));
    const Eigen::Matrix<double, 6, 6> ata = total.ata.selfadjointView<Eigen::Upper>();
    const Eigen::Matrix<double, 6, 1> x = ata.ldlt().solve(total.atb);
    const Eigen::Vector3d rotation_vector = x.head<3>();
    const double angle = rotation_vector.norm();
    Eigen::Matrix4d update = Eigen::Matrix4d::Identity();
    if (angle > 0.0)
      update.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, rotation_vector / angle).matrix();
    update.topRightCorner<3, 1>() = x.tail<3>();
    result.fixed_from_moving = update * result.fixed_from_moving;
    const bool distance_settled = next_distance == max_distance;
    max_distance = next_distance;
    if (distance_settled && x.tail<3>().norm() < options.min_translation_m &&
        angle < options.min_rotation_rad) {
      result.converged = true;
      break;
    }
  }
  result.iterations = std::min(result.iterations, options.max_iterations);
  return result;
}

ScanRegistration RegisterScans(const Scan& fixed, const Scan& moving, const IcpOptions& options,
                               const GlobalAlignOptions* global) {
  // The clouds are float: registered in a frame centred on the fixed scanner, so that survey coordinates (a
  // pose 5,000 km out, where a float step is half a metre) register as well as local ones.
  Eigen::Matrix4d local_from_world = Eigen::Matrix4d::Identity();
  local_from_world.topRightCorner<3, 1>() = -fixed.world_from_scanner.topRightCorner<3, 1>();
  auto in_local_frame = [&](const Scan& scan) {
    Scan local = scan;  // shares the pixels; only the pose differs
    local.world_from_scanner = local_from_world * scan.world_from_scanner;
    return local;
  };
  // Scans without normals get grid normals: oriented toward their scanner, which FPFH needs.
  const NormalOptions grid_normals;
  const Scan fixed_local =
      in_local_frame(fixed.normal.empty() ? WithGridNormals(fixed, grid_normals) : fixed);
  const Scan moving_local =
      in_local_frame(moving.normal.empty() ? WithGridNormals(moving, grid_normals) : moving);
  const PointCloud fixed_in_local = ToPointCloud(fixed_local, true);
  const PointCloud moving_in_local = ToPointCloud(moving_local, true);
  const Eigen::Matrix4d initial =
      global ? AlignGlobally(fixed_in_local, moving_in_local, *global).fixed_from_moving
             : Eigen::Matrix4d::Identity();
  ScanRegistration out;
  out.icp = IcpPointToPlane(fixed_in_local, moving_in_local, initial, options);
  // Back to the world: world_from_local * local correction * local_from_world.
  const Eigen::Matrix4d world_from_local = local_from_world.inverse();
  out.icp.fixed_from_moving = world_from_local * out.icp.fixed_from_moving * local_from_world;
  out.registered = moving;
  out.registered.world_from_scanner = out.icp.fixed_from_moving * moving.world_from_scanner;
  return out;
}

ScanRegistrationSummary SummarizeScanRegistration(const ScanRegistration& registration,
                                                  const GlobalAlignOptions* global) {
  ScanRegistrationSummary summary;
  summary.world_from_scanner = registration.registered.world_from_scanner;
  summary.rms_m = registration.icp.rms_m;
  summary.fitness = registration.icp.fitness;
  summary.iterations = registration.icp.iterations;
  summary.converged = registration.icp.converged;
  if (global != nullptr) summary.global_options = *global;
  return summary;
}

}  // namespace lidarshop
