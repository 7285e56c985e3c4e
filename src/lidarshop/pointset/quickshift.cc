#include "lidarshop/pointset/quickshift.h"

#include <cmath>
#include <vector>

#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// Row-major access to the features of one cell.
struct FeatureImage {
  const float* data;
  int rows, cols, channels;
  const float* At(int row, int col) const {
    return data + (static_cast<int64_t>(row) * cols + col) * channels;
  }
  double FeatureDistanceSq(int r0, int c0, int r1, int c1) const {
    const float* a = At(r0, c0);
    const float* b = At(r1, c1);
    double sum = 0.0;
    for (int k = 0; k < channels; ++k) {
      const double d = static_cast<double>(a[k]) - b[k];
      sum += d * d;
    }
    return sum;
  }
};

}  // namespace

cv::Mat QuickShift(const cv::Mat& features, const cv::Mat& mask, const QuickShiftOptions& options,
                   int* count) {
  if (!(options.kernel_size > 0) || !(options.max_dist > 0)) {
    throw OptionsError("quickshift: kernel_size and max_dist must be > 0");
  }
  if (features.empty() || features.depth() != CV_32F) throw InputError("quickshift: features must be CV_32F");
  if (!mask.empty() && (mask.size() != features.size() || mask.type() != CV_8UC1)) {
    throw InputError("quickshift: the mask must be CV_8U of the features' size");
  }
  const cv::Mat continuous = features.isContinuous() ? features : features.clone();
  const FeatureImage image{continuous.ptr<float>(), continuous.rows, continuous.cols, continuous.channels()};
  const int rows = image.rows, cols = image.cols;
  const auto in = [&](int r, int c) { return mask.empty() || mask.at<uint8_t>(r, c) != 0; };
  const double sigma_sq = options.kernel_size * options.kernel_size;
  const int density_radius = static_cast<int>(std::ceil(3.0 * options.kernel_size));
  const double max_dist_sq = options.max_dist * options.max_dist;
  // A link is never longer than max_dist, and its spatial part is a lower bound of the joint distance.
  const int link_radius = static_cast<int>(std::ceil(options.max_dist));

  std::vector<double> density(static_cast<size_t>(rows) * cols, 0.0);
  ParallelFor(rows, [&](int64_t r64) {
    const int r = static_cast<int>(r64);
    for (int c = 0; c < cols; ++c) {
      if (!in(r, c)) continue;
      double sum = 0.0;
      for (int dr = -density_radius; dr <= density_radius; ++dr) {
        const int rr = r + dr;
        if (rr < 0 || rr >= rows) continue;
        for (int dc = -density_radius; dc <= density_radius; ++dc) {
          const int cc = c + dc;
          if (cc < 0 || cc >= cols || !in(rr, cc)) continue;
          const double d_sq = dr * dr + dc * dc + image.FeatureDistanceSq(r, c, rr, cc);
          sum += std::exp(-d_sq / (2.0 * sigma_sq));
        }
      }
      density[static_cast<size_t>(r) * cols + c] = sum;
    }
  });

  // parent[i] = i for roots and cells outside the mask.
  std::vector<int64_t> parent(density.size());
  ParallelFor(rows, [&](int64_t r64) {
    const int r = static_cast<int>(r64);
    for (int c = 0; c < cols; ++c) {
      const int64_t index = static_cast<int64_t>(r) * cols + c;
      parent[index] = index;
      if (!in(r, c)) continue;
      const double own = density[index];
      double best_sq = max_dist_sq;
      for (int dr = -link_radius; dr <= link_radius; ++dr) {
        const int rr = r + dr;
        if (rr < 0 || rr >= rows) continue;
        for (int dc = -link_radius; dc <= link_radius; ++dc) {
          const int cc = c + dc;
          if (cc < 0 || cc >= cols || !in(rr, cc)) continue;
          const int64_t other = static_cast<int64_t>(rr) * cols + cc;
          const double other_density = density[other];
          if (other_density < own || (other_density == own && other <= index)) continue;
          const double spatial_sq = dr * dr + dc * dc;
          if (spatial_sq >= best_sq) continue;
          const double d_sq = spatial_sq + image.FeatureDistanceSq(r, c, rr, cc);
          // Equal distances: the lower index, so the choice does not depend on the scan order.
          if (d_sq < best_sq || (d_sq == best_sq && parent[index] != index && other < parent[index])) {
            best_sq = d_sq;
            parent[index] = other;
          }
        }
      }
    }
  });

  // Roots numbered in row-major order; every cell takes its root's label. Parents have a higher (density,
  // index), so every path ends; each path is walked once (its cells remember their label).
  cv::Mat labels(rows, cols, CV_32S, cv::Scalar(-1));
  int32_t* out = labels.ptr<int32_t>();
  int32_t next = 0;
  for (size_t i = 0; i < parent.size(); ++i) {
    if (parent[i] == static_cast<int64_t>(i) && in(static_cast<int>(i / cols), static_cast<int>(i % cols))) {
      out[i] = next++;
    }
  }
  std::vector<int64_t> path;
  for (size_t i = 0; i < parent.size(); ++i) {
    if (out[i] >= 0 || !in(static_cast<int>(i / cols), static_cast<int>(i % cols))) continue;
    path.clear();
    int64_t cell = static_cast<int64_t>(i);
    while (out[cell] < 0) {
      path.push_back(cell);
      cell = parent[cell];
    }
    for (const int64_t on_path : path) out[on_path] = out[cell];
  }
  if (count) *count = next;
  return labels;
}

}  // namespace lidarshop
