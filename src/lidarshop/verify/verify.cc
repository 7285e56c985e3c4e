#include "lidarshop/verify/verify.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/pointset/sampling.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {
namespace {

constexpr double kPi = std::numbers::pi;

double WrapAngle(double angle) {
  angle = std::fmod(angle + kPi, 2.0 * kPi);
  if (angle < 0) angle += 2.0 * kPi;
  return angle - kPi;
}

// Slab test of the line origin + t * direction against a box; returns the parameter interval [t0, t1] (t0 >
// t1 when the line misses).
std::pair<float, float> LineBoxInterval(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                                        const Eigen::AlignedBox3f& box) {
  float t0 = -std::numeric_limits<float>::infinity();
  float t1 = std::numeric_limits<float>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (direction[axis] == 0.0f) {
      if (origin[axis] < box.min()[axis] || origin[axis] > box.max()[axis]) return {1.0f, 0.0f};
      continue;
    }
    const float inverse = 1.0f / direction[axis];
    float a = (box.min()[axis] - origin[axis]) * inverse;
    float b = (box.max()[axis] - origin[axis]) * inverse;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return {t0, t1};
  }
  return {t0, t1};
}

// The cells of a scan that can see a box: the columns whose azimuth and the row window whose elevation fall
// inside the box's angular extent seen from the scanner (plus a margin).
struct Footprint {
  std::vector<int> columns;
  int row_begin = 0;
  int row_end = 0;  // exclusive
  int64_t num_cells() const { return static_cast<int64_t>(columns.size()) * (row_end - row_begin); }
};

Footprint FindFootprint(const PreparedScan& prepared, const Eigen::Matrix4d& scanner_from_model,
                        const Eigen::AlignedBox3f& box_in_model, double margin_cells) {
  Footprint footprint;
  const int rows = prepared.scan.rows;
  const int cols = prepared.scan.cols;
  const Eigen::Matrix4d model_from_scanner = scanner_from_model.inverse();
  const Eigen::Vector3f origin_in_model = model_from_scanner.topRightCorner<3, 1>().cast<float>();
  const Eigen::Vector3f up_in_model =
      (model_from_scanner.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitZ()).cast<float>();

  if (box_in_model.contains(origin_in_model)) {
    footprint.columns.resize(cols);
    for (int c = 0; c < cols; ++c) footprint.columns[c] = c;
    footprint.row_end = rows;
    return footprint;
  }
  // Points along the box's 12 edges: the extreme elevation of an edge can lie between its corners.
  constexpr int kEdgeSamples = 8;
  double elevation_min = std::numeric_limits<double>::infinity();
  double elevation_max = -elevation_min;
  std::vector<double> azimuths;
  azimuths.reserve(12 * (kEdgeSamples + 1));
  const Eigen::Vector3f lo = box_in_model.min();
  const Eigen::Vector3f size = box_in_model.sizes();
  const Eigen::Vector3d center_in_scanner =
      (scanner_from_model * box_in_model.center().cast<double>().homogeneous()).head<3>();
  const double azimuth_center = std::atan2(center_in_scanner.x(), center_in_scanner.y());
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3;
    const int a2 = (axis + 2) % 3;
    for (int corner = 0; corner < 4; ++corner) {
      Eigen::Vector3f start = lo;
      if (corner & 1) start[a1] += size[a1];
      if (corner & 2) start[a2] += size[a2];
      for (int s = 0; s <= kEdgeSamples; ++s) {
        Eigen::Vector3f p = start;
        p[axis] += size[axis] * static_cast<float>(s) / kEdgeSamples;
        const Eigen::Vector3d q = (scanner_from_model * p.cast<double>().homogeneous()).head<3>();
        const double norm = q.norm();
        if (norm <= 0) continue;
        const double elevation = std::asin(std::clamp(q.z() / norm, -1.0, 1.0));
        elevation_min = std::min(elevation_min, elevation);
        elevation_max = std::max(elevation_max, elevation);
        azimuths.push_back(WrapAngle(std::atan2(q.x(), q.y()) - azimuth_center));
      }
    }
  }
  double azimuth_lo = *std::min_element(azimuths.begin(), azimuths.end());
  double azimuth_hi = *std::max_element(azimuths.begin(), azimuths.end());
  // The scanner's vertical axis through the box: every azimuth sees it, up to the zenith or nadir.
  const auto [t0, t1] = LineBoxInterval(origin_in_model, up_in_model, box_in_model);
  bool all_azimuths = azimuth_hi - azimuth_lo > 1.8 * kPi;
  if (t0 <= t1) {
    all_azimuths = true;
    if (t1 > 0) elevation_max = kPi / 2;
    if (t0 < 0) elevation_min = -kPi / 2;
  }
  const double azimuth_margin = margin_cells * prepared.azimuth_step_rad;
  const double elevation_margin = margin_cells * prepared.elevation_step_rad;
  for (int c = 0; c < cols; ++c) {
    const double offset = WrapAngle(prepared.column_azimuth_rad[c] - azimuth_center);
    if (all_azimuths || (offset >= azimuth_lo - azimuth_margin && offset <= azimuth_hi + azimuth_margin)) {
      footprint.columns.push_back(c);
    }
  }
  // Elevation decreases down the image; find the contiguous window (robust to a non-monotone fitted grid by
  // taking the first and last row inside).
  footprint.row_begin = rows;
  footprint.row_end = 0;
  for (int r = 0; r < rows; ++r) {
    const double elevation = prepared.row_elevation_rad[r];
    if (elevation >= elevation_min - elevation_margin && elevation <= elevation_max + elevation_margin) {
      footprint.row_begin = std::min(footprint.row_begin, r);
      footprint.row_end = r + 1;
    }
  }
  if (footprint.row_end <= footprint.row_begin) footprint.columns.clear();
  return footprint;
}

// Distances to the first hit (+inf on a miss) of rays that share nothing but coherence (neighbouring cells of
// one scanner): Embree packets of 16, several times faster than one rtcIntersect1 per ray on a big model.
void CastDistances(const RaycastScene& scene, std::span<const Ray> rays, std::span<float> t_hit) {
  RTCScene handle = static_cast<RTCScene>(scene.native_scene());
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RTCRayHit16 packet;
  alignas(64) int valid[16];
  for (size_t start = 0; start < rays.size(); start += 16) {
    const size_t count = std::min<size_t>(16, rays.size() - start);
    for (size_t k = 0; k < 16; ++k) {
      const Ray& ray = rays[start + std::min(k, count - 1)];
      valid[k] = k < count ? -1 : 0;
      packet.ray.org_x[k] = ray.origin.x();
      packet.ray.org_y[k] = ray.origin.y();
      packet.ray.org_z[k] = ray.origin.z();
      packet.ray.dir_x[k] = ray.direction.x();
      packet.ray.dir_y[k] = ray.direction.y();
      packet.ray.dir_z[k] = ray.direction.z();
      packet.ray.tnear[k] = ray.t_near;
      packet.ray.tfar[k] = ray.t_far;
      packet.ray.time[k] = 0.0f;
      packet.ray.mask[k] = 0xFFFFFFFFu;
      packet.ray.flags[k] = 0;
      packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, handle, &context, &packet);
    for (size_t k = 0; k < count; ++k) {
      t_hit[start + k] = packet.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID
                             ? packet.ray.tfar[k]
                             : std::numeric_limits<float>::infinity();
    }
  }
}

// Integer cell coordinates (clamped to the grid) of a point in the kernel cell grid.
Eigen::Vector3i KernelCellCoords(const KernelNeighbourGrid& grid, const Eigen::Vector3f& p) {
  const Eigen::Vector3f cell = (p - grid.origin_in_model) / grid.cell_m;
  return Eigen::Vector3i(std::clamp(static_cast<int>(std::floor(cell.x())), 0, grid.cell_dims.x() - 1),
                         std::clamp(static_cast<int>(std::floor(cell.y())), 0, grid.cell_dims.y() - 1),
                         std::clamp(static_cast<int>(std::floor(cell.z())), 0, grid.cell_dims.z() - 1));
}

int64_t KernelCellOf(const KernelNeighbourGrid& grid, const Eigen::Vector3f& p) {
  const Eigen::Vector3i c = KernelCellCoords(grid, p);
  return (static_cast<int64_t>(c.z()) * grid.cell_dims.y() + c.y()) * grid.cell_dims.x() + c.x();
}

KernelNeighbourGrid BuildKernelGrid(const PointKdTree& tree, const Eigen::AlignedBox3f& bounds,
                                    float kernel_radius, float trim) {
  KernelNeighbourGrid grid;
  grid.kernel_radius_m = kernel_radius;
  grid.trim_m = trim;
  const float reach = std::max(kernel_radius, trim);
  const Eigen::Vector3f lo = bounds.min().array() - reach;
  const Eigen::Vector3f extent = bounds.sizes().array() + 2 * reach;
  constexpr double kMaxVoxels = 2e6;
  grid.voxel_m = std::max(kernel_radius / 3.0f, static_cast<float>(std::cbrt(extent.prod() / kMaxVoxels)));
  grid.origin_in_model = lo;
  for (int k = 0; k < 3; ++k)
    grid.dims[k] = std::max(1, static_cast<int>(std::ceil(extent[k] / grid.voxel_m)));
  const int64_t voxels = static_cast<int64_t>(grid.dims.x()) * grid.dims.y() * grid.dims.z();
  const float half_diagonal = 0.5f * std::sqrt(3.0f) * grid.voxel_m;
  const auto points = tree.points();
  std::vector<std::vector<uint32_t>> nearest_lists(voxels);
  ParallelFor(
      voxels,
      [&](int64_t v) {
        const int x = static_cast<int>(v % grid.dims.x());
        const int y = static_cast<int>((v / grid.dims.x()) % grid.dims.y());
        const int z = static_cast<int>(v / (static_cast<int64_t>(grid.dims.x()) * grid.dims.y()));
        const Eigen::Vector3f centre = lo + grid.voxel_m * Eigen::Vector3f(x + 0.5f, y + 0.5f, z + 0.5f);
        const NearestResult nearest = tree.NearestWithin(centre, trim + half_diagonal);
        if (nearest.found()) {
          const float reach_of_voxel = std::sqrt(nearest.distance_sq) + 2.0f * half_diagonal;
          // A little slack so that float rounding never drops the true nearest point.
          tree.ForEachInRadius(centre, reach_of_voxel * 1.0001f + 1e-6f,
                               [&](uint32_t i, float) { nearest_lists[v].push_back(i); });
          std::sort(nearest_lists[v].begin(), nearest_lists[v].end());
        }
      },
      256);
  grid.nearest_offsets.resize(voxels + 1);
  grid.nearest_offsets[0] = 0;
  for (int64_t v = 0; v < voxels; ++v) {
    grid.nearest_offsets[v + 1] = grid.nearest_offsets[v] + static_cast<uint32_t>(nearest_lists[v].size());
  }
  grid.nearest_indices.reserve(grid.nearest_offsets.back());
  for (auto& list : nearest_lists) {
    grid.nearest_indices.insert(grid.nearest_indices.end(), list.begin(), list.end());
    std::vector<uint32_t>().swap(list);
  }
  grid.nearest_positions.reserve(grid.nearest_indices.size());
  for (uint32_t i : grid.nearest_indices) grid.nearest_positions.push_back(points[i]);

  // Kernel cells: the points sorted by cell (counting sort, stable: ascending index within a cell).
  grid.cell_m = std::max(kernel_radius * 1.001f, static_cast<float>(std::cbrt(extent.prod() / kMaxVoxels)));
  for (int k = 0; k < 3; ++k)
    grid.cell_dims[k] = std::max(1, static_cast<int>(std::ceil(extent[k] / grid.cell_m)));
  const int64_t cells = static_cast<int64_t>(grid.cell_dims.x()) * grid.cell_dims.y() * grid.cell_dims.z();
  std::vector<uint32_t> cell_of(points.size());
  grid.cell_offsets.assign(cells + 1, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    cell_of[i] = static_cast<uint32_t>(KernelCellOf(grid, points[i]));
    ++grid.cell_offsets[cell_of[i] + 1];
  }
  for (int64_t c = 0; c < cells; ++c) grid.cell_offsets[c + 1] += grid.cell_offsets[c];
  std::vector<uint32_t> next(grid.cell_offsets.begin(), grid.cell_offsets.end() - 1);
  grid.cell_indices.resize(points.size());
  grid.cell_positions.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const uint32_t slot = next[cell_of[i]]++;
    grid.cell_indices[slot] = static_cast<uint32_t>(i);
    grid.cell_positions[slot] = points[i];
  }
  return grid;
}

struct Workspace {
  std::vector<Ray> rays;
  std::vector<float> t_hit;
  std::vector<float> ray_range;
  std::vector<int64_t> ray_cell;
};

}  // namespace

void ModelOptions::Check() const {
  CheckOption(num_surface_samples > 0,
              fmt::format("ModelOptions.num_surface_samples must be > 0, got {}", num_surface_samples));
  CheckOption(
      distinctiveness_radius_m >= 0,
      fmt::format("ModelOptions.distinctiveness_radius_m must be >= 0, got {}", distinctiveness_radius_m));
  CheckOption(distinctiveness_floor >= 0 && std::isfinite(distinctiveness_floor),
              fmt::format("ModelOptions.distinctiveness_floor must be >= 0, got {}", distinctiveness_floor));
}

void VerifyOptions::Check() const {
  CheckOption(allowance_m >= 0 && std::isfinite(allowance_m),
              fmt::format("VerifyOptions.allowance_m must be >= 0, got {}", allowance_m));
  CheckOption(sigma_m > 0 && std::isfinite(sigma_m),
              fmt::format("VerifyOptions.sigma_m must be > 0, got {}", sigma_m));
  CheckOption(icp_trim_m > 0 && std::isfinite(icp_trim_m),
              fmt::format("VerifyOptions.icp_trim_m must be > 0, got {}", icp_trim_m));
  CheckOption(footprint_margin_cells >= 0 && footprint_margin_cells < 1000,
              fmt::format("VerifyOptions.footprint_margin_cells must be in [0, 1000), got {}",
                          footprint_margin_cells));
}

VerifierModel PrepareModel(const TriangleMesh& mesh_in_model, const ModelOptions& options) {
  return PrepareModel(mesh_in_model, options, VerifyOptions());
}

VerifierModel PrepareModel(const TriangleMesh& mesh_in_model, const ModelOptions& options,
                           const VerifyOptions& verify_options) {
  options.Check();
  verify_options.Check();
  ValidateMesh(mesh_in_model, "verification model");
  if (mesh_in_model.empty()) throw InputError("verification model: the mesh has no triangles");
  VerifierModel model;
  model.mesh_in_model = mesh_in_model;
  model.surface_area_m2 = SurfaceArea(mesh_in_model);
  if (!(model.surface_area_m2 > 0)) throw InputError("verification model: the mesh has no surface area");
  model.bounds_in_model = Bounds(mesh_in_model);
  // Built once and cast millions of times: the slowest, best BVH pays for itself.
  RaycastSceneOptions raycast_options;
  raycast_options.build_quality = "high";
  model.scene_in_model = RaycastScene(raycast_options);
  model.scene_in_model.AddMesh(mesh_in_model, 0);
  model.scene_in_model.Commit();

  std::vector<Eigen::Vector3f> points;
  if (options.point_source == ModelPointSource::kVertices) {
    points = mesh_in_model.vertices;
  } else {
    points = SampleSurface(mesh_in_model, options.num_surface_samples, options.seed).points;
  }
  model.points_in_model = PointKdTree(std::move(points));
  const size_t n = model.points_in_model.size();
  model.information.assign(n, 1.0f / static_cast<float>(n));
  if (options.information == InformationWeighting::kShapeDistinctiveness) {
    const double radius = options.distinctiveness_radius_m > 0
                              ? options.distinctiveness_radius_m
                              : 0.03 * model.bounds_in_model.diagonal().norm();
    const std::vector<float> variation = SurfaceVariation(model.points_in_model, static_cast<float>(radius));
    double total = 0.0;
    for (size_t i = 0; i < n; ++i) total += variation[i] + options.distinctiveness_floor;
    for (size_t i = 0; i < n; ++i) {
      model.information[i] = static_cast<float>((variation[i] + options.distinctiveness_floor) / total);
    }
  }
  model.kernel_grid = BuildKernelGrid(model.points_in_model, model.bounds_in_model,
                                      static_cast<float>(3.0 * verify_options.sigma_m),
                                      static_cast<float>(verify_options.icp_trim_m));
  return model;
}

PreparedScan PrepareScan(const Scan& scan) {
  CheckScan(scan);
  if (scan.rows <= 0 || scan.cols <= 0) throw InputError(fmt::format("scan '{}': no cells", scan.name));
  PreparedScan prepared;
  prepared.scan = scan;
  prepared.world_from_scanner = scan.world_from_scanner;
  prepared.scanner_from_world = scan.world_from_scanner.inverse();
  prepared.num_valid = scan.CountValid();
  const bool grid_matches = static_cast<int>(scan.grid.azimuth_rad.size()) == scan.cols &&
                            static_cast<int>(scan.grid.elevation_rad.size()) == scan.rows;
  if (grid_matches) {
    prepared.column_azimuth_rad = scan.grid.azimuth_rad;
    prepared.row_elevation_rad = scan.grid.elevation_rad;
  } else {
    // From the direction channel: the middle row for azimuths, the middle column for elevations (falling back
    // to any cell with a direction).
    auto direction_at = [&](int r, int c) {
      const cv::Vec3f d = scan.direction.at<cv::Vec3f>(r, c);
      return Eigen::Vector3f(d[0], d[1], d[2]);
    };
    prepared.column_azimuth_rad.resize(scan.cols);
    for (int c = 0; c < scan.cols; ++c) {
      bool found = false;
      for (int k = 0; k < scan.rows && !found; ++k) {
        const int r = (scan.rows / 2 + (k % 2 == 0 ? k / 2 : -(k + 1) / 2) + scan.rows) % scan.rows;
        const Eigen::Vector3f d = direction_at(r, c);
        if (d.squaredNorm() > 0) {
          prepared.column_azimuth_rad[c] = AzimuthOf(d);
          found = true;
        }
      }
      if (!found) throw InputError(fmt::format("scan '{}': column {} has no ray direction", scan.name, c));
    }
    prepared.row_elevation_rad.resize(scan.rows);
    for (int r = 0; r < scan.rows; ++r) {
      bool found = false;
      for (int k = 0; k < scan.cols && !found; ++k) {
        const int c = (scan.cols / 2 + (k % 2 == 0 ? k / 2 : -(k + 1) / 2) + scan.cols) % scan.cols;
        const Eigen::Vector3f d = direction_at(r, c);
        if (d.squaredNorm() > 0) {
          prepared.row_elevation_rad[r] = ElevationOf(d);
          found = true;
        }
      }
      if (!found) throw InputError(fmt::format("scan '{}': row {} has no ray direction", scan.name, r));
    }
  }
  for (int c = 1; c < scan.cols; ++c) {
    prepared.azimuth_step_rad =
        std::max(prepared.azimuth_step_rad,
                 std::abs(WrapAngle(prepared.column_azimuth_rad[c] - prepared.column_azimuth_rad[c - 1])));
  }
  for (int r = 1; r < scan.rows; ++r) {
    prepared.elevation_step_rad =
        std::max(prepared.elevation_step_rad,
                 std::abs(prepared.row_elevation_rad[r] - prepared.row_elevation_rad[r - 1]));
  }
  if (scan.cols == 1) prepared.azimuth_step_rad = prepared.elevation_step_rad;
  if (scan.rows == 1) prepared.elevation_step_rad = prepared.azimuth_step_rad;
  return prepared;
}

VerifyResult VerifyPose(const VerifierModel& model, std::span<const PreparedScan> scans,
                        const Eigen::Matrix4d& world_from_model, const VerifyOptions& options) {
  LIDARSHOP_CHECK(model.scene_in_model.committed());
  options.Check();
  thread_local Workspace workspace;
  VerifyResult result;
  const size_t n = model.num_points();
  const float allowance = static_cast<float>(options.allowance_m);
  const float sigma = static_cast<float>(options.sigma_m);
  const float kernel_radius = 3.0f * sigma;
  const float inverse_two_sigma_sq = 1.0f / (2.0f * sigma * sigma);
  const float trim = static_cast<float>(options.icp_trim_m);
  const float near_radius = std::max(kernel_radius, trim);
  Eigen::AlignedBox3f near_box = model.bounds_in_model;
  near_box.min().array() -= near_radius;
  near_box.max().array() += near_radius;
  Eigen::AlignedBox3f icp_box = model.bounds_in_model;
  icp_box.min().array() -= trim;
  icp_box.max().array() += trim;
  const Eigen::Matrix4d model_from_world = world_from_model.inverse();
  const KernelNeighbourGrid& grid = model.kernel_grid;
  // The grid covers the model's box grown by max(3σ, trim); only points inside near_box (the same box) use
  // it.
  const bool use_grid = grid.built() &&
                        std::abs(grid.kernel_radius_m - kernel_radius) <= 1e-6f * kernel_radius &&
                        std::abs(grid.trim_m - trim) <= 1e-6f * trim;

  std::vector<float> observed_sum(n, 0.0f);  // Σ_j exp(−d²/2σ²) over all scans
  std::vector<float> scan_sum;               // the same for one scan (only with several scans)
  double icp_distance_sum = 0.0;
  result.per_scan.resize(scans.size());
  if (options.keep_details) result.scene_status.resize(scans.size());

  for (size_t s = 0; s < scans.size(); ++s) {
    const PreparedScan& prepared = scans[s];
    const Scan& scan = prepared.scan;
    ScanVerifyStats& stats = result.per_scan[s];
    if (options.keep_details) result.scene_status[s] = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
    const bool separate = scans.size() > 1;
    if (separate) scan_sum.assign(n, 0.0f);
    std::vector<float>& sum = separate ? scan_sum : observed_sum;

    const Eigen::Matrix4d scanner_from_model = prepared.scanner_from_world * world_from_model;
    const Eigen::Matrix4d model_from_scanner = model_from_world * prepared.world_from_scanner;
    const Eigen::Matrix3f linear = model_from_scanner.topLeftCorner<3, 3>().cast<float>();
    const Eigen::Vector3f origin = model_from_scanner.topRightCorner<3, 1>().cast<float>();
    const Footprint footprint =
        FindFootprint(prepared, scanner_from_model, near_box, options.footprint_margin_cells);
    stats.footprint_cells = footprint.num_cells();

    workspace.rays.clear();
    workspace.ray_range.clear();
    workspace.ray_cell.clear();
    for (int r = footprint.row_begin; r < footprint.row_end; ++r) {
      const uint8_t* valid = scan.valid.ptr<uint8_t>(r);
      const float* range = scan.range.ptr<float>(r);
      const cv::Vec3f* point = scan.point.ptr<cv::Vec3f>(r);
      for (int c : footprint.columns) {
        if (valid[c] == 0 || !(range[c] > 0)) continue;
        const Eigen::Vector3f point_in_scanner(point[c][0], point[c][1], point[c][2]);
        const Eigen::Vector3f point_in_model = linear * point_in_scanner + origin;
        const Eigen::Vector3f direction_in_model = linear * (point_in_scanner / range[c]);
        // Consistency: only rays that meet the model's box can meet the model.
        const auto [t0, t1] = LineBoxInterval(origin, direction_in_model, model.bounds_in_model);
        if (t0 <= t1 && t1 >= 0) {
          Ray ray;
          ray.origin = origin;
          ray.direction = direction_in_model;
          workspace.rays.push_back(ray);
          workspace.ray_range.push_back(range[c]);
          workspace.ray_cell.push_back(static_cast<int64_t>(r) * scan.cols + c);
        }
        // Confidence and ICP: scene points near the model, looked up in the model's KD-tree.
        // One radius search serves both when a model point lies within 3σ (the usual case for points on the
        // object): its closest match is the ICP nearest neighbour too.
        if (!near_box.contains(point_in_model)) continue;
        float closest_sq = std::numeric_limits<float>::infinity();
        if (use_grid) {
          // The 3 x 3 x 3 kernel cells around the point's own: nine runs of three cells, contiguous in x.
          const Eigen::Vector3i c = KernelCellCoords(grid, point_in_model);
          const int x0 = std::max(c.x() - 1, 0), x1 = std::min(c.x() + 1, grid.cell_dims.x() - 1);
          const float kernel_radius_sq = kernel_radius * kernel_radius;
          for (int z = std::max(c.z() - 1, 0); z <= std::min(c.z() + 1, grid.cell_dims.z() - 1); ++z) {
            for (int y = std::max(c.y() - 1, 0); y <= std::min(c.y() + 1, grid.cell_dims.y() - 1); ++y) {
              const int64_t row = (static_cast<int64_t>(z) * grid.cell_dims.y() + y) * grid.cell_dims.x();
              const uint32_t end = grid.cell_offsets[row + x1 + 1];
              for (uint32_t k = grid.cell_offsets[row + x0]; k < end; ++k) {
                const float distance_sq = (grid.cell_positions[k] - point_in_model).squaredNorm();
                if (distance_sq < kernel_radius_sq) {
                  const uint32_t i = grid.cell_indices[k];
                  // Only min(1, sum) matters: a saturated point needs no more exp (exact, and most of the
                  // cost).
                  if (sum[i] < 1.0f) sum[i] += std::exp(-distance_sq * inverse_two_sigma_sq);
                  closest_sq = std::min(closest_sq, distance_sq);
                }
              }
            }
          }
        } else {
          model.points_in_model.ForEachInRadius(point_in_model, kernel_radius,
                                                [&](uint32_t i, float distance_sq) {
                                                  if (sum[i] < 1.0f)
                                                    sum[i] += std::exp(-distance_sq * inverse_two_sigma_sq);
                                                  closest_sq = std::min(closest_sq, distance_sq);
                                                });
        }
        if (!icp_box.contains(point_in_model)) continue;
        ++result.icp_candidates;
        if (!(closest_sq < kernel_radius * kernel_radius)) {
          if (use_grid) {
            const Eigen::Vector3f cell = (point_in_model - grid.origin_in_model) / grid.voxel_m;
            const int x = std::clamp(static_cast<int>(cell.x()), 0, grid.dims.x() - 1);
            const int y = std::clamp(static_cast<int>(cell.y()), 0, grid.dims.y() - 1);
            const int z = std::clamp(static_cast<int>(cell.z()), 0, grid.dims.z() - 1);
            const int64_t voxel = (static_cast<int64_t>(z) * grid.dims.y() + y) * grid.dims.x() + x;
            for (uint32_t k = grid.nearest_offsets[voxel]; k < grid.nearest_offsets[voxel + 1]; ++k) {
              closest_sq = std::min(closest_sq, (grid.nearest_positions[k] - point_in_model).squaredNorm());
            }
          } else {
            closest_sq = model.points_in_model.NearestWithin(point_in_model, trim).distance_sq;
          }
        }
        if (closest_sq <= trim * trim) {
          ++result.icp_inliers;
          icp_distance_sum += std::sqrt(closest_sq);
        }
      }
    }
    workspace.t_hit.resize(workspace.rays.size());
    CastDistances(model.scene_in_model, workspace.rays, workspace.t_hit);
    stats.rays_cast = static_cast<int64_t>(workspace.rays.size());
    for (size_t k = 0; k < workspace.rays.size(); ++k) {
      const float t_hit = workspace.t_hit[k];
      if (!std::isfinite(t_hit)) continue;
      ++stats.comparable_pairs;
      const bool consistent = (t_hit + allowance) - workspace.ray_range[k] >= 0.0f;
      if (consistent) ++stats.consistent_pairs;
      if (options.keep_details) {
        result.scene_status[s].data[workspace.ray_cell[k]] = consistent ? kConsistent : kInconsistent;
      }
    }
    if (stats.comparable_pairs > 0) {
      stats.consistency = static_cast<double>(stats.consistent_pairs) / stats.comparable_pairs;
    }
    result.comparable_pairs += stats.comparable_pairs;
    result.consistent_pairs += stats.consistent_pairs;
    double confidence = 0.0;
    for (size_t i = 0; i < n; ++i) confidence += model.information[i] * std::min(1.0f, sum[i]);
    stats.confidence = confidence;
    if (separate) {
      for (size_t i = 0; i < n; ++i) observed_sum[i] += scan_sum[i];
    }
  }

  result.has_comparable_pairs = result.comparable_pairs > 0;
  if (result.has_comparable_pairs) {
    result.consistency = static_cast<double>(result.consistent_pairs) / result.comparable_pairs;
  }
  double confidence = 0.0;
  if (options.keep_details) result.observed_information.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const float observed = model.information[i] * std::min(1.0f, observed_sum[i]);
    confidence += observed;
    if (options.keep_details) result.observed_information[i] = observed;
  }
  result.confidence = std::min(1.0, confidence);
  if (result.icp_inliers > 0) result.icp_cost_m = icp_distance_sum / result.icp_inliers;
  if (result.icp_candidates > 0) {
    result.inlier_fraction = static_cast<double>(result.icp_inliers) / result.icp_candidates;
  }
  return result;
}

std::vector<VerifyResult> VerifyPoses(const VerifierModel& model, std::span<const PreparedScan> scans,
                                      std::span<const Eigen::Matrix4d> world_from_model,
                                      const VerifyOptions& options, Progress* progress) {
  options.Check();
  std::vector<VerifyResult> results(world_from_model.size());
  ParallelFor(
      static_cast<int64_t>(world_from_model.size()),
      [&](int64_t p) {
        results[p] = VerifyPose(model, scans, world_from_model[p], options);
        Advance(progress);
      },
      4);
  return results;
}

std::string VerifyResult::BriefReport() const {
  const std::string consistency_text =
      has_comparable_pairs ? fmt::format("{:.3f}", consistency) : std::string("n/a (no comparable pair)");
  return fmt::format("consistency {} ({} of {} pairs), confidence {:.3f}, icp {} (inliers {:.3f})",
                     consistency_text, consistent_pairs, comparable_pairs, confidence,
                     std::isnan(icp_cost_m) ? std::string("n/a") : fmt::format("{:.4f} m", icp_cost_m),
                     inlier_fraction);
}

PointCloud SceneStatusCloud(std::span<const PreparedScan> scans, const VerifyResult& result) {
  if (result.scene_status.size() != scans.size()) {
    throw std::invalid_argument("SceneStatusCloud: the result was computed without keep_details");
  }
  PointCloud cloud;
  for (size_t s = 0; s < scans.size(); ++s) {
    const Scan& scan = scans[s].scan;
    for (int r = 0; r < scan.rows; ++r) {
      for (int c = 0; c < scan.cols; ++c) {
        if (scan.valid.at<uint8_t>(r, c) == 0) continue;
        const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
        cloud.points.push_back(
            TransformPoint(scans[s].world_from_scanner, Eigen::Vector3f(p[0], p[1], p[2])));
        const uint8_t status = result.scene_status[s].at<uint8_t>(r, c);
        cloud.colors.push_back(status == kConsistent     ? Rgb8(40, 200, 40)
                               : status == kInconsistent ? Rgb8(230, 30, 30)
                                                         : Rgb8(150, 150, 150));
        cloud.labels.push_back(status);
      }
    }
  }
  return cloud;
}

PointCloud ObservedModelCloud(const VerifierModel& model, const Eigen::Matrix4d& world_from_model,
                              const VerifyResult& result) {
  if (result.observed_information.size() != model.num_points()) {
    throw std::invalid_argument("ObservedModelCloud: the result was computed without keep_details");
  }
  PointCloud cloud;
  const auto points = model.points_in_model.points();
  for (size_t i = 0; i < points.size(); ++i) {
    cloud.points.push_back(TransformPoint(world_from_model, points[i]));
    const float seen =
        model.information[i] > 0 ? result.observed_information[i] / model.information[i] : 0.0f;
    const float t = std::clamp(seen, 0.0f, 1.0f);
    cloud.colors.push_back(Rgb8(static_cast<uint8_t>(std::lround(230 * (1 - t) + 30 * t)),
                                static_cast<uint8_t>(std::lround(30 * (1 - t) + 200 * t)), 30));
    cloud.intensities.push_back(t);
  }
  return cloud;
}

Eigen::Matrix4d PoseFromXyzYaw(double x_m, double y_m, double z_m, double yaw_deg, double pitch_deg,
                               double roll_deg) {
  const double to_rad = kPi / 180.0;
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(yaw_deg * to_rad, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(pitch_deg * to_rad, Eigen::Vector3d::UnitX()) *
                                    Eigen::AngleAxisd(roll_deg * to_rad, Eigen::Vector3d::UnitY()))
                                       .toRotationMatrix();
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose.topLeftCorner<3, 3>() = rotation;
  pose.topRightCorner<3, 1>() = Eigen::Vector3d(x_m, y_m, z_m);
  return pose;
}

}  // namespace lidarshop
