#include "lidarshop/pointset/filters.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <unordered_map>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void CheckCloudHasPoints(const PointCloud& cloud, int64_t count, std::string_view what) {
  if (cloud.empty()) throw InputError(fmt::format("{}: the point cloud is empty", what));
  if (static_cast<int64_t>(cloud.size()) < count) {
    throw InputError(
        fmt::format("{}: needs at least {} points, the cloud has {}", what, count, cloud.size()));
  }
}

void CheckCloudHasShape(const PointCloud& cloud, std::string_view what) {
  CheckCloudHasPoints(cloud, 1, what);
  const Eigen::Vector3f& first = cloud.points.front();
  const bool all_same = std::all_of(cloud.points.begin(), cloud.points.end(),
                                    [&](const Eigen::Vector3f& p) { return p == first; });
  if (all_same) throw InputError(fmt::format("{}: all {} points are identical", what, cloud.size()));
}

void StatisticalOutlierOptions::Check() const { Validate(*this); }

void RadiusOutlierOptions::Check() const { Validate(*this); }

void CropOptions::Check() const {
  Validate(*this);
  CheckOption(polygon.empty() || polygon.size() >= 3,
              fmt::format("crop polygon: needs at least 3 corners, got {}", polygon.size()));
  CheckOption(!box || !box->isEmpty(), "crop box: empty (min > max)");
}

std::vector<uint8_t> StatisticalOutlierInliers(const PointCloud& cloud,
                                               const StatisticalOutlierOptions& options) {
  options.Check();
  CheckCloudHasPoints(cloud, 1, "statistical outlier removal");
  if (options.neighbors >= static_cast<int64_t>(cloud.size())) {
    throw InputError(
        fmt::format("statistical outlier removal: {} neighbours asked, the cloud has only {} points",
                    options.neighbors, cloud.size()));
  }
  const PointKdTree tree(cloud.points);
  std::vector<double> mean_distance(cloud.size());
  ParallelForRange(
      static_cast<int64_t>(cloud.size()),
      [&](int64_t begin, int64_t end) {
        std::vector<uint32_t> indices;
        std::vector<float> distances_sq;
        for (int64_t i = begin; i < end; ++i) {
          tree.KNearest(cloud.points[i], options.neighbors + 1, &indices, &distances_sq);
          double sum = 0.0;  // the first match is the point itself (distance 0)
          for (size_t n = 1; n < distances_sq.size(); ++n) sum += std::sqrt(distances_sq[n]);
          mean_distance[i] = sum / options.neighbors;
        }
      },
      1024);
  // Serial sums: the threshold must not depend on the thread count.
  const double n = static_cast<double>(cloud.size());
  const double mean = std::accumulate(mean_distance.begin(), mean_distance.end(), 0.0) / n;
  double variance = 0.0;
  for (double d : mean_distance) variance += (d - mean) * (d - mean);
  const double sigma = cloud.size() > 1 ? std::sqrt(variance / (n - 1.0)) : 0.0;
  const double threshold = mean + options.std_ratio * sigma;
  std::vector<uint8_t> keep(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) keep[i] = mean_distance[i] <= threshold;
  return keep;
}

std::vector<uint8_t> RadiusOutlierInliers(const PointCloud& cloud, const RadiusOutlierOptions& options) {
  options.Check();
  CheckCloudHasPoints(cloud, 1, "radius outlier removal");
  const PointKdTree tree(cloud.points);
  const float radius = static_cast<float>(options.radius_m);
  std::vector<uint8_t> keep(cloud.size());
  ParallelFor(
      static_cast<int64_t>(cloud.size()),
      [&](int64_t i) {
        int count = -1;  // the point itself is found too
        tree.ForEachInRadius(cloud.points[i], radius, [&](uint32_t, float) { ++count; });
        keep[i] = count >= options.min_neighbors;
      },
      1024);
  return keep;
}

namespace {

// Even-odd rule on the polygon's (x, y).
bool InsidePolygon(const std::vector<Eigen::Vector2f>& polygon, float x, float y) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2f& a = polygon[i];
    const Eigen::Vector2f& b = polygon[j];
    if ((a.y() > y) != (b.y() > y) && x < (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

}  // namespace

std::vector<uint8_t> CropInliers(const PointCloud& cloud, const CropOptions& options) {
  options.Check();
  const bool by_intensity = options.min_intensity > 0.0 || options.max_intensity < 1.0;
  if (!options.labels.empty() && cloud.labels.size() != cloud.size()) {
    throw InputError("crop by label: the cloud has no labels");
  }
  if (by_intensity && cloud.intensities.size() != cloud.size()) {
    throw InputError("crop by intensity: the cloud has no intensities");
  }
  const double min_sq = options.min_range_m * options.min_range_m;
  const double max_sq = options.max_range_m * options.max_range_m;
  std::vector<uint8_t> keep(cloud.size());
  ParallelFor(
      static_cast<int64_t>(cloud.size()),
      [&](int64_t i) {
        const Eigen::Vector3f& p = cloud.points[i];
        bool pass = !options.box || options.box->contains(p);
        if (pass && !options.polygon.empty()) pass = InsidePolygon(options.polygon, p.x(), p.y());
        if (pass && !options.labels.empty()) {
          pass = std::find(options.labels.begin(), options.labels.end(), cloud.labels[i]) !=
                 options.labels.end();
        }
        if (pass && (min_sq > 0.0 || max_sq > 0.0)) {
          const double range_sq = (p - options.origin).cast<double>().squaredNorm();
          pass = range_sq >= min_sq && (max_sq == 0.0 || range_sq <= max_sq);
        }
        if (pass && by_intensity) {
          pass =
              cloud.intensities[i] >= options.min_intensity && cloud.intensities[i] <= options.max_intensity;
        }
        keep[i] = pass != options.invert;
      },
      4096);
  return keep;
}

PointCloud SelectPoints(const PointCloud& cloud, const std::vector<uint8_t>& keep) {
  LIDARSHOP_CHECK(keep.size() == cloud.size());
  PointCloud out;
  auto copy = [&](const auto& from, auto& to) {
    if (from.size() != cloud.size()) return;
    for (size_t i = 0; i < keep.size(); ++i) {
      if (keep[i]) to.push_back(from[i]);
    }
  };
  copy(cloud.points, out.points);
  copy(cloud.normals, out.normals);
  copy(cloud.colors, out.colors);
  copy(cloud.intensities, out.intensities);
  copy(cloud.labels, out.labels);
  copy(cloud.synthesized, out.synthesized);
  return out;
}

Scan KeepScanCells(const Scan& scan, const std::vector<int64_t>& cell_index,
                   const std::vector<uint8_t>& keep) {
  LIDARSHOP_CHECK(keep.size() == cell_index.size());
  cv::Mat keep_mask(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  for (size_t i = 0; i < keep.size(); ++i) {
    if (keep[i])
      keep_mask.at<uint8_t>(static_cast<int>(cell_index[i] / scan.cols), cell_index[i] % scan.cols) = 255;
  }
  return MaskScan(scan, keep_mask);
}

PointCloud VoxelDownsample(const PointCloud& cloud, double voxel_m) {
  CheckOption(voxel_m > 0.0, fmt::format("voxel size must be > 0 m, got {}", voxel_m));
  CheckCloudHasPoints(cloud, 1, "voxel subsampling");
  const Eigen::Vector3f origin = Bounds(cloud).min();
  struct Accumulator {
    Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero(),
                    color = Eigen::Vector3d::Zero();
    double intensity = 0.0;
    int64_t count = 0;
    size_t first = 0;
  };
  std::unordered_map<uint64_t, size_t> slot_of_voxel;
  std::vector<Accumulator> voxels;
  slot_of_voxel.reserve(cloud.size() / 4);
  const bool normals = cloud.normals.size() == cloud.size(), colors = cloud.colors.size() == cloud.size(),
             intensities = cloud.intensities.size() == cloud.size();
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d cell = ((cloud.points[i] - origin).cast<double>() / voxel_m).array().floor();
    if (cell.maxCoeff() >= (1 << 21))
      throw OptionsError(fmt::format("voxel size {} m is too small for the cloud", voxel_m));
    const uint64_t key = (static_cast<uint64_t>(cell.x()) << 42) | (static_cast<uint64_t>(cell.y()) << 21) |
                         static_cast<uint64_t>(cell.z());
    auto [it, inserted] = slot_of_voxel.try_emplace(key, voxels.size());
    if (inserted) voxels.push_back({.first = i});
    Accumulator& voxel = voxels[it->second];
    voxel.point += cloud.points[i].cast<double>();
    if (normals) voxel.normal += cloud.normals[i].cast<double>();
    if (colors) voxel.color += cloud.colors[i].cast<double>();
    if (intensities) voxel.intensity += cloud.intensities[i];
    ++voxel.count;
  }
  PointCloud out;
  for (const Accumulator& voxel : voxels) {
    const double n = static_cast<double>(voxel.count);
    out.points.push_back((voxel.point / n).cast<float>());
    if (normals) out.normals.push_back(voxel.normal.normalized().cast<float>());
    if (colors) out.colors.push_back((voxel.color / n).array().round().cast<uint8_t>());
    if (intensities) out.intensities.push_back(static_cast<float>(voxel.intensity / n));
    if (cloud.labels.size() == cloud.size()) out.labels.push_back(cloud.labels[voxel.first]);
    if (cloud.synthesized.size() == cloud.size()) out.synthesized.push_back(cloud.synthesized[voxel.first]);
  }
  return out;
}

std::vector<uint8_t> RandomSampleInliers(const PointCloud& cloud, int64_t count, uint64_t seed) {
  CheckOption(count >= 0, fmt::format("random sample count must be >= 0, got {}", count));
  std::vector<uint8_t> keep(cloud.size(), 1);
  if (count >= static_cast<int64_t>(cloud.size())) return keep;
  // Floyd's algorithm with our own integer draws: the same choice on every standard library.
  std::mt19937_64 random(seed);
  std::fill(keep.begin(), keep.end(), 0);
  const uint64_t n = cloud.size();
  for (uint64_t j = n - count; j < n; ++j) {
    const uint64_t t = random() % (j + 1);
    if (keep[t]) {
      keep[j] = 1;
    } else {
      keep[t] = 1;
    }
  }
  return keep;
}

Scan TransformScan(const Scan& scan, const Eigen::Matrix4d& b_from_world) {
  CheckOption(IsRigid(b_from_world, 1e-5), "the transform of a scan must be rigid (rotation + translation)");
  Scan out = scan;
  out.world_from_scanner = b_from_world * scan.world_from_scanner;
  return out;
}

PointCloud MergeClouds(const std::vector<PointCloud>& clouds) {
  PointCloud out;
  auto all_have = [&](auto member) {
    return std::all_of(clouds.begin(), clouds.end(),
                       [&](const PointCloud& c) { return (c.*member).size() == c.size(); });
  };
  const bool normals = all_have(&PointCloud::normals), colors = all_have(&PointCloud::colors),
             intensities = all_have(&PointCloud::intensities), labels = all_have(&PointCloud::labels),
             synthesized = all_have(&PointCloud::synthesized);
  for (const PointCloud& c : clouds) {
    out.points.insert(out.points.end(), c.points.begin(), c.points.end());
    if (normals) out.normals.insert(out.normals.end(), c.normals.begin(), c.normals.end());
    if (colors) out.colors.insert(out.colors.end(), c.colors.begin(), c.colors.end());
    if (intensities)
      out.intensities.insert(out.intensities.end(), c.intensities.begin(), c.intensities.end());
    if (labels) out.labels.insert(out.labels.end(), c.labels.begin(), c.labels.end());
    if (synthesized)
      out.synthesized.insert(out.synthesized.end(), c.synthesized.begin(), c.synthesized.end());
  }
  if (out.empty()) throw InputError("merge: every cloud is empty");
  return out;
}

}  // namespace lidarshop
