#include "lidarshop/verify/sweep_bound.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop::verify_internal {
namespace {

constexpr double kRelativeMargin = 1e-4;       // on radii: verify works in float
constexpr double kAbsoluteMargin = 1e-4;       // metres
constexpr double kMaxBytes = double{1 << 26};  // the distance bytes of all windows

}  // namespace

SweepConfidenceBound::SweepConfidenceBound(const VerifierModel& model, std::span<const PreparedScan> scans,
                                           const SweepOptions& options, double sigma_m, double max_radius_m) {
  kernel_m_ = 3.0 * sigma_m * (1.0 + kRelativeMargin) + kAbsoluteMargin;
  const auto points = model.points_in_model.points();
  LIDARSHOP_CHECK(!points.empty());
  double reach_xy = 0.0, z_lo = std::numeric_limits<double>::infinity(), z_hi = -z_lo;
  // Lowest first: the ground reaches them, so a block that cannot be skipped usually stops early; and
  // neighbours in z share a window of slabs (cache).
  std::vector<uint32_t> order(points.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return points[a].z() < points[b].z(); });
  points_in_model_.reserve(points.size());
  information_.reserve(points.size());
  for (uint32_t i : order) {
    const Eigen::Vector3f& p = points[i];
    points_in_model_.push_back(p.cast<double>());
    information_.push_back(model.information[i]);
    reach_xy = std::max(reach_xy, std::hypot(double{p.x()}, double{p.y()}));
    z_lo = std::min(z_lo, double{p.z()});
    z_hi = std::max(z_hi, double{p.z()});
  }

  // Columns of about σ square (finer would not tighten a bound whose kernel is 3σ; coarser when the region
  // is large) and slabs of σ / 5: a car's sills and tyres lie within centimetres of 3σ above the ground, so
  // the vertical test must be nearly exact (horizontally, the ground is everywhere anyway).
  const double radius = max_radius_m * (1.0 + kRelativeMargin) + kAbsoluteMargin;
  const double pad = reach_xy + radius + kernel_m_;
  const double width = options.x_max_m - options.x_min_m + 2 * pad;
  const double depth = options.y_max_m - options.y_min_m + 2 * pad;
  const double height = z_hi - z_lo + 2 * kernel_m_;
  slab_m_ = std::max(sigma_m / 5.0, height / 4096.0);
  nz_ = static_cast<int>(std::ceil(height / slab_m_)) + 4;
  cell_m_ = std::max({sigma_m, 1e-3, std::sqrt(width * depth * nz_ / kMaxBytes)});
  x0_m_ = options.x_min_m - pad - 2 * cell_m_;
  y0_m_ = options.y_min_m - pad - 2 * cell_m_;
  z0_m_ = options.z_m + z_lo - kernel_m_ - 2 * slab_m_;
  nx_ = static_cast<int>(std::ceil(width / cell_m_)) + 4;
  ny_ = static_cast<int>(std::ceil(depth / cell_m_)) + 4;
  const int words = (nz_ + 63) / 64;
  const size_t columns = static_cast<size_t>(nx_) * ny_;
  CheckMemoryBudget(
      static_cast<int64_t>(columns) * (nz_ + 8 * words + 8),
      fmt::format("the confidence bound of a coarse-to-fine sweep ({} x {} columns of {:.3f} m, {} "
                  "slabs of {:.3f} m)",
                  nx_, ny_, cell_m_, nz_, slab_m_));

  // Per column, one bit per slab holding a scene point.
  std::vector<uint64_t> bits(columns * words, 0);
  for (const PreparedScan& prepared : scans) {
    const Scan& scan = prepared.scan;
    const Eigen::Matrix4d& world_from_scanner = prepared.world_from_scanner;
    for (int r = 0; r < scan.rows; ++r) {
      for (int c = 0; c < scan.cols; ++c) {
        if (scan.valid.at<uint8_t>(r, c) == 0 || !(scan.range.at<float>(r, c) > 0)) continue;
        const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
        const Eigen::Vector3d q = (world_from_scanner * Eigen::Vector4d(p[0], p[1], p[2], 1.0)).head<3>();
        const double fx = std::floor((q.x() - x0_m_) / cell_m_), fy = std::floor((q.y() - y0_m_) / cell_m_);
        const double fz = std::floor((q.z() - z0_m_) / slab_m_);
        if (!(fx >= 0 && fx < nx_ && fy >= 0 && fy < ny_ && fz >= 0 && fz < nz_)) continue;
        const size_t column = static_cast<size_t>(fy) * nx_ + static_cast<size_t>(fx);
        const int k = static_cast<int>(fz);
        bits[column * words + k / 64] |= uint64_t{1} << (k % 64);
      }
    }
  }

  // Each model point needs the window of slabs its z ± 3σ touches, starting at its first slab.
  first_slab_.resize(points_in_model_.size());
  std::vector<uint8_t> used(nz_, 0);
  for (size_t i = 0; i < points_in_model_.size(); ++i) {
    const double z = options.z_m + points_in_model_[i].z();
    first_slab_[i] = std::clamp(static_cast<int>(std::floor((z - kernel_m_ - z0_m_) / slab_m_)), 0, nz_ - 1);
    used[first_slab_[i]] = 1;
  }
  const int window = static_cast<int>(std::floor(2 * kernel_m_ / slab_m_)) + 2;
  window_distance_.assign(nz_, cv::Mat());
  std::vector<int> starts;
  for (int k = 0; k < nz_; ++k) {
    if (used[k]) starts.push_back(k);
  }
  ParallelFor(static_cast<int64_t>(starts.size()), [&](int64_t s) {
    const int k = starts[s];
    std::vector<uint64_t> mask(words, 0);
    for (int slab = k; slab < std::min(nz_, k + window); ++slab)
      mask[slab / 64] |= uint64_t{1} << (slab % 64);
    // 0 where the column holds a point of the window (distanceTransform measures to zero pixels).
    cv::Mat occupied(ny_, nx_, CV_8U, cv::Scalar(255));
    bool any = false;
    for (size_t column = 0; column < columns; ++column) {
      uint64_t hit = 0;
      for (int w = 0; w < words; ++w) hit |= bits[column * words + w] & mask[w];
      if (hit != 0) {
        occupied.data[column] = 0;
        any = true;
      }
    }
    if (!any) return;
    // The exact Euclidean distance transform (DIST_MASK_PRECISE with DIST_L2), in cells, kept as bytes
    // rounded down and capped at 255 (both only make the distance smaller: the bound stays above).
    cv::Mat distance;
    cv::distanceTransform(occupied, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    cv::Mat floored(ny_, nx_, CV_8U);
    for (int y = 0; y < ny_; ++y) {
      for (int x = 0; x < nx_; ++x) {
        floored.at<uint8_t>(y, x) =
            static_cast<uint8_t>(std::min(255.0f, std::floor(distance.at<float>(y, x))));
      }
    }
    window_distance_[k] = floored;
  });
  window_of_point_.resize(points_in_model_.size());
  for (size_t i = 0; i < points_in_model_.size(); ++i) {
    const cv::Mat& distance = window_distance_[first_slab_[i]];
    window_of_point_[i] = distance.empty() ? nullptr : distance.data;
  }
  yaws_deg_ = options.yaws_deg;
  rotated_cells_.resize(yaws_deg_.size());
  for (size_t k = 0; k < yaws_deg_.size(); ++k) rotated_cells_[k] = RotatedCells(yaws_deg_[k]);
}

std::vector<Eigen::Vector2d> SweepConfidenceBound::RotatedCells(double yaw_deg) const {
  const Eigen::Matrix2d rotation = PoseFromXyzYaw(0.0, 0.0, 0.0, yaw_deg).topLeftCorner<2, 2>();
  std::vector<Eigen::Vector2d> cells(points_in_model_.size());
  for (size_t i = 0; i < cells.size(); ++i) cells[i] = rotation * points_in_model_[i].head<2>() / cell_m_;
  return cells;
}

double SweepConfidenceBound::UpperBound(double x_m, double y_m, double yaw_deg, double radius_m,
                                        double stop_above) const {
  std::vector<Eigen::Vector2d> computed;
  const std::vector<Eigen::Vector2d>* rotated = nullptr;
  for (size_t k = 0; k < yaws_deg_.size() && rotated == nullptr; ++k) {
    if (yaws_deg_[k] == yaw_deg) rotated = &rotated_cells_[k];
  }
  if (rotated == nullptr) {
    computed = RotatedCells(yaw_deg);
    rotated = &computed;
  }
  const double reach_m = radius_m * (1.0 + kRelativeMargin) + kAbsoluteMargin + kernel_m_;
  // Occupied cells D apart hold points at least (D − √2 − 1) cells apart (see the header); D is stored
  // rounded down, so compare with the whole cells below the reach.
  const double reach_cells = reach_m / cell_m_ + std::sqrt(2.0) + 1.0;
  const uint8_t limit = static_cast<uint8_t>(std::min(255.0, std::floor(reach_cells)));
  const bool all_near = reach_cells >= 255.0;
  // The model points' cell coordinates are (rotated + centre) in cells from the grid's corner.
  const double cx = (x_m - x0_m_) / cell_m_, cy = (y_m - y0_m_) / cell_m_;
  double bound = 0.0;
  for (size_t i = 0; i < rotated->size(); ++i) {
    const double fx = std::floor((*rotated)[i].x() + cx), fy = std::floor((*rotated)[i].y() + cy);
    bool near = true;  // outside the grid (not expected): counted
    if (fx >= 0 && fx < nx_ && fy >= 0 && fy < ny_) {
      const uint8_t* distance = window_of_point_[i];
      near = distance != nullptr &&
             (all_near || distance[static_cast<size_t>(fy) * nx_ + static_cast<size_t>(fx)] <= limit);
    }
    if (near) {
      bound += information_[i];
      if (bound > stop_above) return bound;
    }
  }
  return bound;
}

}  // namespace lidarshop::verify_internal
