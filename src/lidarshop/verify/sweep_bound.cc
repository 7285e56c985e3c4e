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
  points_in_model_.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    points_in_model_.push_back(p.cast<double>());
    reach_xy = std::max(reach_xy, std::hypot(double{p.x()}, double{p.y()}));
    z_lo = std::min(z_lo, double{p.z()});
    z_hi = std::max(z_hi, double{p.z()});
  }
  information_.assign(model.information.begin(), model.information.end());

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
}

double SweepConfidenceBound::UpperBound(double x_m, double y_m, double yaw_deg, double radius_m,
                                        double stop_above) const {
  const Eigen::Matrix4d pose = PoseFromXyzYaw(x_m, y_m, 0.0, yaw_deg);
  const Eigen::Matrix2d rotation = pose.topLeftCorner<2, 2>();
  const double reach_m = radius_m * (1.0 + kRelativeMargin) + kAbsoluteMargin + kernel_m_;
  // Occupied cells D apart hold points at least (D − √2 − 1) cells apart (see the header).
  const float reach_cells = static_cast<float>(reach_m / cell_m_ + std::sqrt(2.0) + 1.0);
  double bound = 0.0;
  for (size_t i = 0; i < points_in_model_.size(); ++i) {
    const Eigen::Vector2d p = rotation * points_in_model_[i].head<2>() + Eigen::Vector2d(x_m, y_m);
    const double fx = std::floor((p.x() - x0_m_) / cell_m_), fy = std::floor((p.y() - y0_m_) / cell_m_);
    bool near = true;  // outside the grid (not expected): counted
    if (fx >= 0 && fx < nx_ && fy >= 0 && fy < ny_) {
      const cv::Mat& distance = window_distance_[first_slab_[i]];
      near = !distance.empty() &&
             distance.at<uint8_t>(static_cast<int>(fy), static_cast<int>(fx)) <= reach_cells;
    }
    if (near) {
      bound += information_[i];
      if (bound > stop_above) return bound;
    }
  }
  return bound;
}

}  // namespace lidarshop::verify_internal
