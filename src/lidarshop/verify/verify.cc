#include "lidarshop/verify/verify.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/pointset/sampling.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/verify/footprint_gather.h"
#include "lidarshop/verify/kernel_grid.h"

namespace lidarshop {
namespace {

constexpr double kPi = std::numbers::pi;

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

// The consistency status of rays (model frame; t_near = just before the model's box) whose scene points lie
// at distance `limit` + a along them (limit = d_s − a), by two occlusion (any-hit) queries instead of one
// closest-hit query: (d_m + a) − d_s < 0 ⇔ the model has surface on [0, limit).
//   1. surface on [0, limit]?  → inconsistent. Skipped when limit is before the box (it cannot be).
//   2. otherwise, surface on [limit, ∞)?  → consistent; else the ray misses the model: not comparable.
// An any-hit query stops at the first triangle it meets, and the first one ends 10 cm (a) short of the
// surface that the scene point usually lies on, so it prunes early; together they cost ~30 % less than the
// closest hit here (bench/results/verify.md). Rays go in Embree packets of 16 neighbouring cells.
using verify_internal::FootprintRays;

void ClassifyRays(const RaycastScene& scene, const Eigen::Vector3f& origin, const FootprintRays& rays,
                  std::span<uint8_t> status) {
  const size_t num_rays = rays.size;
  RTCScene handle = static_cast<RTCScene>(scene.native_scene());
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RTCRay16 packet;
  for (int lane = 0; lane < 16; ++lane) {
    packet.org_x[lane] = origin.x();
    packet.org_y[lane] = origin.y();
    packet.org_z[lane] = origin.z();
    packet.time[lane] = 0.0f;
    packet.mask[lane] = 0xFFFFFFFFu;
    packet.flags[lane] = 0;
  }
  alignas(64) int active[16];
  for (size_t start = 0; start < num_rays; start += 16) {
    const size_t count = std::min<size_t>(16, num_rays - start);
    bool any_active = false;
    for (size_t lane = 0; lane < 16; ++lane) {
      const size_t k = start + std::min(lane, count - 1);
      active[lane] = lane < count && rays.limit[k] > rays.t_near[k] ? -1 : 0;
      any_active |= active[lane] != 0;
      packet.dir_x[lane] = rays.dir_x[k];
      packet.dir_y[lane] = rays.dir_y[k];
      packet.dir_z[lane] = rays.dir_z[k];
      packet.tnear[lane] = rays.t_near[k];
      packet.tfar[lane] = rays.limit[k];
    }
    if (any_active) rtcOccluded16(active, handle, &context, &packet);
    any_active = false;
    for (size_t lane = 0; lane < 16; ++lane) {
      const size_t k = start + std::min(lane, count - 1);
      const bool occluded =
          active[lane] != 0 && packet.tfar[lane] < 0;  // Embree marks a hit with tfar = −inf
      if (lane < count) status[k] = occluded ? kInconsistent : kNotComparable;
      active[lane] = lane < count && !occluded ? -1 : 0;
      any_active |= active[lane] != 0;
      packet.tnear[lane] = std::max(rays.t_near[k], rays.limit[k]);
      packet.tfar[lane] = std::numeric_limits<float>::infinity();
    }
    if (any_active) rtcOccluded16(active, handle, &context, &packet);
    for (size_t lane = 0; lane < count; ++lane) {
      if (active[lane] != 0 && packet.tfar[lane] < 0) status[start + lane] = kConsistent;
    }
  }
}

struct Workspace {
  FootprintRays rays;
  verify_internal::NearPoints near;
  std::vector<Eigen::Vector3f> near_points;  // scene points inside the near box, model frame, in scan order
  std::vector<float> closest_sq;             // per near point: squared distance to the nearest model point
  std::vector<Eigen::Vector3f> far_points;   // near points in the ICP box without a model point within 3σ
  std::vector<uint32_t> far_index;           // their index among the near points
  std::vector<float> far_closest_sq;
  std::vector<uint8_t> status;  // per ray: SceneStatus
};

// The quantities of a VerifyPose call that do not depend on the scan. Lengths in the model frame are in
// model units: metres divided by the pose's scale (world metres = model units · metres_per_unit).
struct PoseQuery {
  double metres_per_unit = 1.0;    // the uniform scale s of world_from_model
  float allowance = 0;             // a, metres: applied along the rays, whose parameter stays in metres
  float sigma = 0;                 // σ, model units
  float kernel_radius = 0;         // 3σ, model units
  float inverse_two_sigma_sq = 0;  // 1 / 2σ², per model unit²
  float trim = 0;                  // ICP trim distance, model units
  Eigen::AlignedBox3f near_box;    // the model's box grown by max(3σ, trim), model frame
  Eigen::AlignedBox3f icp_box;     // the model's box grown by trim
  // The kernel grid covers the model's box grown by max(3σ, trim); only points inside near_box (the same box)
  // use it, and only when it was built for these radii.
  bool use_grid = false;
};

PoseQuery MakePoseQuery(const VerifierModel& model, const VerifyOptions& options, double metres_per_unit) {
  PoseQuery q;
  q.metres_per_unit = metres_per_unit;
  q.allowance = static_cast<float>(options.allowance_m);
  q.sigma = static_cast<float>(options.sigma_m / metres_per_unit);
  q.kernel_radius = 3.0f * q.sigma;
  q.inverse_two_sigma_sq = 1.0f / (2.0f * q.sigma * q.sigma);
  q.trim = static_cast<float>(options.icp_trim_m / metres_per_unit);
  const float near_radius = std::max(q.kernel_radius, q.trim);
  q.near_box = model.bounds_in_model;
  q.near_box.min().array() -= near_radius;
  q.near_box.max().array() += near_radius;
  q.icp_box = model.bounds_in_model;
  q.icp_box.min().array() -= q.trim;
  q.icp_box.max().array() += q.trim;
  const KernelNeighbourGrid& grid = model.kernel_grid;
  q.use_grid = grid.built() && std::abs(grid.kernel.radius_m - q.kernel_radius) <= 1e-6f * q.kernel_radius &&
               std::abs(grid.icp.radius_m - q.trim) <= 1e-6f * q.trim;
  return q;
}

// The rays of `footprint`'s valid cells that meet the model's box and the scene points inside the near box,
// model frame (workspace->rays, workspace->near, workspace->near_points). Bands of kBandRows rows, column
// after column within a band: consecutive rays are neighbouring cells in a small block (coherent Embree
// packets) and consecutive points stay in the same kernel cells.
void GatherFootprint(const PreparedScan& prepared, const Footprint& footprint,
                     const verify_internal::GatherFrame& frame, Workspace* workspace) {
  static_assert(PreparedScan::kBandRows == 4, "footprint_gather.cc assumes bands of 4 rows");
  constexpr int kBandRows = PreparedScan::kBandRows;
  workspace->rays.size = 0;
  workspace->near.size = 0;
  verify_internal::ReserveGather(
      static_cast<size_t>(footprint.num_cells()) + kBandRows * footprint.columns.size(), workspace->rays,
      workspace->near);
  for (int band = footprint.row_begin / kBandRows * kBandRows; band < footprint.row_end; band += kBandRows) {
    // Runs of consecutive footprint columns (one run, or two where the footprint wraps around ±180°).
    for (size_t first = 0; first < footprint.columns.size();) {
      size_t last = first;
      while (last + 1 < footprint.columns.size() &&
             footprint.columns[last + 1] == footprint.columns[last] + 1) {
        ++last;
      }
      const int first_col = footprint.columns[first];
      verify_internal::GatherBand(prepared.band_cells.data() + prepared.BandCellIndex(band, first_col), band,
                                  footprint.row_begin, footprint.row_end, first_col,
                                  static_cast<int>(last - first + 1), prepared.scan.cols, frame,
                                  workspace->rays, workspace->near);
      first = last + 1;
    }
  }
  const size_t num_near = workspace->near.size;
  workspace->near_points.resize(num_near);
  for (size_t j = 0; j < num_near; ++j) {
    workspace->near_points[j] =
        Eigen::Vector3f(workspace->near.x[j], workspace->near.y[j], workspace->near.z[j]);
  }
}

// Confidence: adds Σ_j exp(−d²/2σ²) over the near points j to `sum` (per model point, in the kernel grid's
// order with the grid, by point index without it), and sets workspace->closest_sq to each near point's
// squared distance to the nearest model point within 3σ (infinity when there is none). One kernel search
// serves both: the closest model point within 3σ is the ICP nearest neighbour too.
void AccumulateKernelSums(const VerifierModel& model, const PoseQuery& q, Workspace* workspace, float* sum) {
  const size_t num_near = workspace->near_points.size();
  const float kernel_radius_sq = q.kernel_radius * q.kernel_radius;
  workspace->closest_sq.assign(num_near, std::numeric_limits<float>::infinity());
  if (q.use_grid) {
    verify_internal::AccumulateKernel(model.kernel_grid, workspace->near_points, kernel_radius_sq,
                                      q.inverse_two_sigma_sq, sum, workspace->closest_sq.data());
    return;
  }
  for (size_t j = 0; j < num_near; ++j) {
    model.points_in_model.ForEachInRadius(
        workspace->near_points[j], q.kernel_radius, [&](uint32_t i, float distance_sq) {
          if (sum[i] < 1.0f) sum[i] += verify_internal::KernelExp(-distance_sq * q.inverse_two_sigma_sq);
          workspace->closest_sq[j] = std::min(workspace->closest_sq[j], distance_sq);
        });
  }
}

// ICP: the near points inside the ICP box are candidates, those within `trim` of the model inliers. The
// candidates without a model point within 3σ (not found by AccumulateKernelSums) get a nearest-neighbour
// search of their own. Adds to the result's counts and to *icp_distance_sum (model units).
void CountIcpInliers(const VerifierModel& model, const PoseQuery& q, Workspace* workspace,
                     VerifyResult* result, double* icp_distance_sum) {
  const size_t num_near = workspace->near_points.size();
  const float kernel_radius_sq = q.kernel_radius * q.kernel_radius;
  workspace->far_points.clear();
  workspace->far_index.clear();
  for (size_t j = 0; j < num_near; ++j) {
    if (q.icp_box.contains(workspace->near_points[j]) && !(workspace->closest_sq[j] < kernel_radius_sq)) {
      workspace->far_points.push_back(workspace->near_points[j]);
      workspace->far_index.push_back(static_cast<uint32_t>(j));
    }
  }
  workspace->far_closest_sq.resize(workspace->far_points.size());
  if (q.use_grid) {
    verify_internal::NearestSquaredDistance(model.kernel_grid, workspace->far_points,
                                            workspace->far_closest_sq.data());
  } else {
    for (size_t f = 0; f < workspace->far_points.size(); ++f) {
      workspace->far_closest_sq[f] =
          model.points_in_model.NearestWithin(workspace->far_points[f], q.trim).distance_sq;
    }
  }
  for (size_t f = 0; f < workspace->far_points.size(); ++f) {
    workspace->closest_sq[workspace->far_index[f]] = workspace->far_closest_sq[f];
  }
  for (size_t j = 0; j < num_near; ++j) {
    if (!q.icp_box.contains(workspace->near_points[j])) continue;
    ++result->icp_candidates;
    if (workspace->closest_sq[j] <= q.trim * q.trim) {
      ++result->icp_inliers;
      *icp_distance_sum += std::sqrt(workspace->closest_sq[j]);
    }
  }
}

// Consistency: classifies the gathered rays against the posed model (`origin`: the scanner in the model
// frame) and counts them into `stats`; with `scene_status` (CV_8U, the scan's size), writes each comparable
// ray's status into its cell.
void CountRayStatus(const VerifierModel& model, const Eigen::Vector3f& origin, Workspace* workspace,
                    ScanVerifyStats* stats, cv::Mat* scene_status) {
  const size_t num_rays = workspace->rays.size;
  workspace->status.resize(num_rays);
  ClassifyRays(model.scene_in_model, origin, workspace->rays, workspace->status);
  stats->rays_cast = static_cast<int64_t>(num_rays);
  for (size_t k = 0; k < num_rays; ++k) {
    const uint8_t status = workspace->status[k];
    if (status == kNotComparable) continue;
    ++stats->comparable_pairs;
    if (status == kConsistent) ++stats->consistent_pairs;
    if (scene_status != nullptr) scene_status->data[workspace->rays.cell[k]] = status;
  }
  if (stats->comparable_pairs > 0) {
    stats->consistency = static_cast<double>(stats->consistent_pairs) / stats->comparable_pairs;
  }
}

}  // namespace

void ModelOptions::Check() const {
  Validate(*this);
  // A model point costs its position, weight, normal and grid entry (~64 bytes).
  CheckMemoryBudget(SaturatingBytes(num_surface_samples, 64),
                    fmt::format("{} model surface samples", num_surface_samples));
}

void VerifyOptions::Check() const { Validate(*this); }

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
  if (options.model_scale != 1.0) {
    for (Eigen::Vector3f& vertex : model.mesh_in_model.vertices) {
      vertex = (vertex.cast<double>() * options.model_scale).cast<float>();
    }
    ValidateMesh(model.mesh_in_model, "verification model (scaled by model_scale)");
  }
  model.surface_area_m2 = SurfaceArea(model.mesh_in_model);
  if (!(model.surface_area_m2 > 0)) throw InputError("verification model: the mesh has no surface area");
  model.bounds_in_model = Bounds(model.mesh_in_model);
  // Built once and cast millions of times: the slowest, best BVH pays for itself.
  RaycastSceneOptions raycast_options;
  raycast_options.build_quality = "high";
  raycast_options.robust = false;  // ~8 % faster; a ray grazing an edge decides nothing here
  model.scene_in_model = RaycastScene(raycast_options);
  model.scene_in_model.AddMesh(model.mesh_in_model, 0);
  model.scene_in_model.Commit();

  std::vector<Eigen::Vector3f> points;
  if (options.point_source == ModelPointSource::kVertices) {
    points = model.mesh_in_model.vertices;
  } else {
    points = SampleSurface(model.mesh_in_model, options.num_surface_samples, options.seed).points;
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
  model.kernel_grid = verify_internal::BuildKernelGrid(model.points_in_model.points(), model.bounds_in_model,
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
  const int bands = (scan.rows + PreparedScan::kBandRows - 1) / PreparedScan::kBandRows;
  prepared.band_cells.assign(static_cast<size_t>(bands) * PreparedScan::kBandRows * scan.cols,
                             Eigen::Vector4f::Zero());
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      const float range = scan.range.at<float>(r, c);
      if (scan.valid.at<uint8_t>(r, c) == 0 || !(range > 0)) continue;
      const cv::Vec3f& p = scan.point.at<cv::Vec3f>(r, c);
      if (!std::isfinite(range) || !std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        throw InputError(fmt::format(
            "scan '{}': row {}, column {}: a return with a non-finite point or range", scan.name, r, c));
      }
      prepared.band_cells[prepared.BandCellIndex(r, c)] = Eigen::Vector4f(p[0], p[1], p[2], range);
    }
  }
  {
    ScanGrid grid = GridOf(scan);
    prepared.column_azimuth_rad = std::move(grid.azimuth_rad);
    prepared.row_elevation_rad = std::move(grid.elevation_rad);
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
  const std::string pose_problem = PoseProblem(world_from_model, /*allow_uniform_scale=*/true);
  if (!pose_problem.empty()) {
    throw std::invalid_argument(fmt::format("VerifyPose: world_from_model {}", pose_problem));
  }
  thread_local Workspace workspace;
  VerifyResult result;
  const size_t n = model.num_points();
  const PoseQuery q =
      MakePoseQuery(model, options, std::cbrt(world_from_model.topLeftCorner<3, 3>().determinant()));
  const Eigen::Matrix4d model_from_world = world_from_model.inverse();
  const KernelNeighbourGrid& grid = model.kernel_grid;

  // Σ_j exp(−d²/2σ²) per model point: in the kernel grid's sorted order with the grid (so that its vector
  // loop reads 8 neighbouring sums at once), by point index without it.
  auto point_of_slot = [&](size_t k) {
    return q.use_grid ? grid.kernel.indices[k] : static_cast<uint32_t>(k);
  };
  std::vector<float> observed_sum(n, 0.0f);  // over all scans
  std::vector<float> scan_sum;               // the same for one scan (only with several scans)
  double icp_distance_sum = 0.0;
  result.per_scan.resize(scans.size());
  if (options.keep_details) result.scene_status.resize(scans.size());

  for (size_t s = 0; s < scans.size(); ++s) {
    const PreparedScan& prepared = scans[s];
    const Scan& scan = prepared.scan;
    ScanVerifyStats& stats = result.per_scan[s];
    stats.scan = scan.name;
    if (options.keep_details) result.scene_status[s] = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
    const bool separate = scans.size() > 1;
    if (separate) scan_sum.assign(n, 0.0f);
    std::vector<float>& sum = separate ? scan_sum : observed_sum;

    const Eigen::Matrix4d scanner_from_model = prepared.scanner_from_world * world_from_model;
    const Eigen::Matrix4d model_from_scanner = model_from_world * prepared.world_from_scanner;
    const Eigen::Matrix3f linear = model_from_scanner.topLeftCorner<3, 3>().cast<float>();
    const Eigen::Vector3f origin = model_from_scanner.topRightCorner<3, 1>().cast<float>();
    const Footprint footprint =
        FindFootprint(prepared, scanner_from_model, q.near_box, options.footprint_margin_cells);
    stats.footprint_cells = footprint.num_cells();
    const verify_internal::GatherFrame frame{linear, origin, model.bounds_in_model, q.near_box, q.allowance};
    GatherFootprint(prepared, footprint, frame, &workspace);
    AccumulateKernelSums(model, q, &workspace, sum.data());
    CountIcpInliers(model, q, &workspace, &result, &icp_distance_sum);
    CountRayStatus(model, origin, &workspace, &stats,
                   options.keep_details ? &result.scene_status[s] : nullptr);
    result.comparable_pairs += stats.comparable_pairs;
    result.consistent_pairs += stats.consistent_pairs;
    double confidence = 0.0;
    for (size_t k = 0; k < n; ++k) confidence += model.information[point_of_slot(k)] * std::min(1.0f, sum[k]);
    stats.confidence = confidence;
    if (separate) {
      for (size_t k = 0; k < n; ++k) observed_sum[k] += scan_sum[k];
    }
  }

  result.has_comparable_pairs = result.comparable_pairs > 0;
  if (result.has_comparable_pairs) {
    result.consistency = static_cast<double>(result.consistent_pairs) / result.comparable_pairs;
  }
  double confidence = 0.0;
  if (options.keep_details) result.observed_information.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const uint32_t i = point_of_slot(k);
    const float observed = model.information[i] * std::min(1.0f, observed_sum[k]);
    confidence += observed;
    if (options.keep_details) result.observed_information[i] = observed;
  }
  result.confidence = std::min(1.0, confidence);
  if (result.icp_inliers > 0) result.icp_cost_m = q.metres_per_unit * icp_distance_sum / result.icp_inliers;
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

VerifyReport MakeVerifyReport(const VerifyResult& result, const VerifierModel& model,
                              const ModelOptions& model_options, const Eigen::Matrix4d& world_from_model) {
  VerifyReport report;
  report.result = result;
  report.result.per_scan.clear();
  report.result.scene_status.clear();
  report.result.observed_information.clear();
  report.icp_cost = result.icp_cost_m;
  report.per_scan = result.per_scan;
  report.world_from_model = RoundedPose(world_from_model);
  report.model_points = static_cast<int64_t>(model.num_points());
  report.model_options = model_options;
  return report;
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
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose.topLeftCorner<3, 3>() = RotationFromEulerDegrees(Eigen::Vector3d(roll_deg, pitch_deg, yaw_deg));
  pose.topRightCorner<3, 1>() = Eigen::Vector3d(x_m, y_m, z_m);
  return pose;
}

}  // namespace lidarshop
