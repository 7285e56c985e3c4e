// Filters, normals, RANSAC planes and clustering on synthetic clouds whose answer is known: a plane with a
// known normal plus outliers, well-separated blobs with known membership; bad inputs get clear errors.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "lidarshop/pointset/clustering.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/hough_planes.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

const Eigen::Vector3d kPlaneNormal = Eigen::Vector3d(1, 2, 5).normalized();
constexpr double kPlaneOffset = -0.7;

// `inliers` points on the plane n·x + d = 0 (within ±noise), then `outliers` uniform in a 4 m cube.
PointCloud PlaneWithOutliers(int inliers, int outliers, double noise_m, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0), jitter(-noise_m, noise_m);
  const Eigen::Vector3d u = kPlaneNormal.unitOrthogonal(), v = kPlaneNormal.cross(u);
  PointCloud cloud;
  for (int i = 0; i < inliers; ++i) {
    const Eigen::Vector3d p = -kPlaneOffset * kPlaneNormal + uniform(random) * u + uniform(random) * v +
                              jitter(random) * kPlaneNormal;
    cloud.points.push_back(p.cast<float>());
  }
  for (int i = 0; i < outliers; ++i) {
    cloud.points.emplace_back(uniform(random), uniform(random), uniform(random) + 5.0);
  }
  return cloud;
}

// `count` blobs of `per` points (σ = 0.05 m) with centres 2 m apart along x.
PointCloud Blobs(int count, int per, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<float> normal(0.0f, 0.05f);
  PointCloud cloud;
  for (int b = 0; b < count; ++b) {
    for (int i = 0; i < per; ++i)
      cloud.points.emplace_back(2.0f * b + normal(random), normal(random), normal(random));
  }
  return cloud;
}

TEST(FiltersTest, OutlierRemovalDropsTheScatteredPoints) {
  const PointCloud cloud = PlaneWithOutliers(20000, 200, 0.001, 1);
  for (const std::vector<uint8_t>& keep :
       {StatisticalOutlierInliers(cloud, {.neighbors = 10, .std_ratio = 2.0}),
        RadiusOutlierInliers(cloud, {.radius_m = 0.08, .min_neighbors = 3})}) {
    const int64_t kept_inliers = std::count(keep.begin(), keep.begin() + 20000, 1);
    const int64_t kept_outliers = std::count(keep.begin() + 20000, keep.end(), 1);
    EXPECT_GT(kept_inliers, 19800);
    EXPECT_LT(kept_outliers, 20);
  }
}

TEST(FiltersTest, VoxelRandomCropMergeAndTransform) {
  PointCloud cloud;
  for (int i = 0; i < 10; ++i) cloud.points.emplace_back(0.01f * i, 0.0f, 0.0f);  // one 0.5 m voxel
  cloud.points.emplace_back(3.0f, 0.0f, 0.0f);
  cloud.labels = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2};
  const PointCloud voxels = VoxelDownsample(cloud, 0.5);
  ASSERT_EQ(voxels.size(), 2u);
  EXPECT_NEAR(voxels.points[0].x(), 0.045f, 1e-6f);
  EXPECT_EQ(voxels.labels, (std::vector<int32_t>{1, 2}));

  const std::vector<uint8_t> sample = RandomSampleInliers(cloud, 4, 7);
  EXPECT_EQ(std::count(sample.begin(), sample.end(), 1), 4);
  EXPECT_EQ(sample, RandomSampleInliers(cloud, 4, 7));

  CropOptions crop;
  crop.box = Eigen::AlignedBox3f(Eigen::Vector3f(-1, -1, -1), Eigen::Vector3f(0.05f, 1, 1));
  EXPECT_EQ(SelectPoints(cloud, CropInliers(cloud, crop)).size(), 6u);
  crop.invert = true;
  EXPECT_EQ(SelectPoints(cloud, CropInliers(cloud, crop)).size(), 5u);
  CropOptions by_label{.labels = {2}};
  EXPECT_EQ(SelectPoints(cloud, CropInliers(cloud, by_label)).points.front().x(), 3.0f);
  CropOptions by_polygon{.polygon = {{2, -1}, {4, -1}, {4, 1}, {2, 1}}};
  EXPECT_EQ(SelectPoints(cloud, CropInliers(cloud, by_polygon)).size(), 1u);
  CropOptions by_range{.min_range_m = 0.035, .max_range_m = 1.0};
  EXPECT_EQ(SelectPoints(cloud, CropInliers(cloud, by_range)).size(), 6u);
  EXPECT_THROW(CropInliers(cloud, CropOptions{.min_intensity = 0.5}), InputError);

  const PointCloud merged = MergeClouds({cloud, voxels});
  EXPECT_EQ(merged.size(), 13u);
  EXPECT_EQ(merged.labels.size(), 13u);
  EXPECT_THROW(MergeClouds({PointCloud()}), InputError);
  Scan scan;
  EXPECT_THROW(TransformScan(scan, Eigen::Matrix4d::Identity() * 2.0), OptionsError);
}

TEST(NormalsTest, PlaneNormalsFaceTheViewpointAndCurvatureIsZero) {
  const PointCloud cloud = PlaneWithOutliers(5000, 0, 0.0, 2);
  NormalOptions options;
  options.viewpoint = (kPlaneNormal * 10.0).cast<float>();
  for (double radius : {0.0, 0.2}) {
    options.radius_m = radius;
    const NormalResult result = EstimateNormals(cloud, options);
    for (size_t i = 0; i < cloud.size(); i += 97) {
      EXPECT_GT(result.normals[i].cast<double>().dot(kPlaneNormal), 0.99999) << i;
      EXPECT_LT(result.curvature[i], 1e-5f);
    }
  }
}

// Surface variation on a sphere of radius r over a ball neighbourhood of radius R: the neighbours fill a
// cap of height h = R² / (2r) whose covariance has λ0 = r²η²/12 along the normal and λ1 = λ2 = r²(η − η²/3)/2
// across it (η = h / r, cos θ uniform over the cap), so λ0 / (λ0 + λ1 + λ2) = η / (12 − 3η) ≈ R² / (24 r²).
TEST(NormalsTest, SphereCurvatureIsTheCapsSurfaceVariation) {
  const double r = 1.0, R = 0.2;
  const Eigen::Vector3f centre(3, -2, 1);
  PointCloud sphere;  // a Fibonacci lattice: nearly uniform, so every neighbourhood is close to the ideal cap
  const int count = 20000;
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count, phi = M_PI * (1.0 + std::sqrt(5.0)) * (i + 0.5);
    const double rho = std::sqrt(1.0 - z * z);
    sphere.points.push_back(centre +
                            (r * Eigen::Vector3d(rho * std::cos(phi), rho * std::sin(phi), z)).cast<float>());
  }
  NormalOptions options;
  options.radius_m = R;
  options.max_neighbors = 0;  // every point within R
  options.viewpoint = centre;
  const NormalResult result = EstimateNormals(sphere, options);
  const double eta = R * R / (2.0 * r * r), expected = eta / (12.0 - 3.0 * eta);
  std::vector<float> sorted = result.curvature;
  std::nth_element(sorted.begin(), sorted.begin() + count / 2, sorted.end());
  EXPECT_NEAR(sorted[count / 2], expected, 0.01 * expected);
  for (int i = 0; i < count; ++i) {
    ASSERT_NEAR(result.curvature[i], expected, 0.06 * expected) << i;
    // Toward the centre (the viewpoint) and radial.
    const Eigen::Vector3f inward = (centre - sphere.points[i]).normalized();
    ASSERT_GT(result.normals[i].dot(inward), 0.999f) << i;
  }
  // A plane of the same sampling has none (PlaneNormalsFaceTheViewpointAndCurvatureIsZero), a smaller sphere more.
  PointCloud small = sphere;
  for (Eigen::Vector3f& p : small.points) p = centre + 0.5f * (p - centre);
  std::vector<float> smaller = EstimateNormals(small, options).curvature;
  const double eta_small = R * R / (2.0 * 0.5 * 0.5), expected_small = eta_small / (12.0 - 3.0 * eta_small);
  std::nth_element(smaller.begin(), smaller.begin() + count / 2, smaller.end());
  EXPECT_NEAR(smaller[count / 2], expected_small, 0.02 * expected_small);
}

TEST(NormalsTest, SameNormalsOnOneThreadAndOnAll) {
  const PointCloud cloud = PlaneWithOutliers(3000, 300, 0.01, 3);
  const NormalResult all = EstimateNormals(cloud, {});
  ThreadLimit one(1);
  const NormalResult single = EstimateNormals(cloud, {});
  EXPECT_EQ(all.normals, single.normals);
  EXPECT_EQ(all.curvature, single.curvature);
}

TEST(PlanesTest, RansacFindsTheKnownPlane) {
  const PointCloud cloud = PlaneWithOutliers(10000, 5000, 0.002, 4);
  const PlaneFit fit = FitPlaneRansac(cloud, {.distance_threshold_m = 0.01, .seed = 5});
  const double sign = fit.normal.dot(kPlaneNormal) > 0 ? 1.0 : -1.0;
  EXPECT_GT(sign * fit.normal.dot(kPlaneNormal), 0.99995);
  EXPECT_NEAR(sign * fit.offset_m, kPlaneOffset, 1e-3);
  EXPECT_GE(fit.inliers.size(), 10000u);
  EXPECT_LT(fit.inliers.size(), 10020u);
  EXPECT_LT(fit.inliers.back(), 10000u + 100u);
  ThreadLimit one(1);
  EXPECT_EQ(FitPlaneRansac(cloud, {.distance_threshold_m = 0.01, .seed = 5}).inliers, fit.inliers);
}

TEST(PlanesTest, SequentialDetectionFindsTwoPlanes) {
  PointCloud cloud = PlaneWithOutliers(6000, 0, 0.001, 6);
  for (int i = 0; i < 4000; ++i)
    cloud.points.emplace_back(0.001f * (i % 100) - 5.0f, 0.001f * (i / 100), 3.0f);
  const std::vector<PlaneFit> planes =
      DetectPlanesRansac(cloud, {.distance_threshold_m = 0.005, .min_inliers = 100, .max_planes = 5});
  ASSERT_EQ(planes.size(), 2u);
  EXPECT_EQ(planes[0].inliers.size(), 6000u);
  EXPECT_NEAR(planes[1].inliers.size(), 4000u, 10);  // a few outliers lie within 1 cm of z = 3
  EXPECT_NEAR(std::abs(planes[1].normal.z()), 1.0, 1e-9);
}

TEST(PlanesTest, HoughFindsTheKnownPlanes) {
  PointCloud cloud = PlaneWithOutliers(6000, 500, 0.002, 10);
  for (int i = 0; i < 4000; ++i) cloud.points.emplace_back(0.01f * (i % 100) - 5.0f, 0.01f * (i / 100), 3.0f);
  const std::vector<PlaneFit> planes =
      DetectPlanesHough(cloud, {.distance_step_m = 0.02, .max_planes = 3, .min_inliers = 500});
  ASSERT_EQ(planes.size(), 2u);
  EXPECT_GT(std::abs(planes[0].normal.dot(kPlaneNormal)), 0.9999);
  EXPECT_NEAR(std::abs(planes[0].offset_m), std::abs(kPlaneOffset), 0.002);
  EXPECT_NEAR(planes[0].inliers.size(), 6000u, 10);
  EXPECT_NEAR(std::abs(planes[1].normal.z()), 1.0, 1e-6);
  EXPECT_NEAR(planes[1].inliers.size(), 4000u, 10);  // a few outliers lie within 1 cm of z = 3
  ThreadLimit one(1);
  EXPECT_EQ(
      DetectPlanesHough(cloud, {.distance_step_m = 0.02, .max_planes = 3, .min_inliers = 500})[0].inliers,
      planes[0].inliers);
}

TEST(ClusteringTest, EuclideanClustersMatchTheBlobs) {
  PointCloud cloud = Blobs(4, 500, 7);
  cloud.points.emplace_back(20.0f, 0.0f, 0.0f);  // a lone point: noise with min_points
  const ClusterResult result = EuclideanClusters(cloud, {.radius_m = 0.3, .min_points = 10});
  ASSERT_EQ(result.num_clusters(), 4);
  for (int b = 0; b < 4; ++b) {
    const int32_t label = result.labels[b * 500];
    EXPECT_EQ(std::count(result.labels.begin(), result.labels.end(), label), 500);
    for (int i = 0; i < 500; ++i) ASSERT_EQ(result.labels[b * 500 + i], label);
  }
  EXPECT_EQ(result.labels.back(), kNoCluster);
  ThreadLimit one(1);
  EXPECT_EQ(EuclideanClusters(cloud, {.radius_m = 0.3, .min_points = 10}).labels, result.labels);
}

TEST(ClusteringTest, KMeansPlusPlusSeparatesTheBlobs) {
  const PointCloud cloud = Blobs(3, 400, 8);
  const KMeansResult result = KMeans(cloud, {.clusters = 3, .seed = 9});
  for (int b = 0; b < 3; ++b) {
    for (int i = 0; i < 400; ++i) ASSERT_EQ(result.labels[b * 400 + i], result.labels[b * 400]);
    EXPECT_NEAR(result.centers[result.labels[b * 400]].x(), 2.0 * b, 0.02);
  }
  EXPECT_EQ(KMeans(cloud, {.clusters = 3, .seed = 9}).labels, result.labels);
}

TEST(BadInputTest, ClearErrors) {
  const PointCloud empty;
  PointCloud same;
  same.points.assign(50, Eigen::Vector3f(1, 2, 3));
  const PointCloud small = Blobs(1, 5, 1);
  EXPECT_THROW(EstimateNormals(empty, {}), InputError);
  EXPECT_THROW(EstimateNormals(same, {}), InputError);
  EXPECT_THROW(FitPlaneRansac(same, {}), InputError);
  EXPECT_THROW(EstimateNormals(small, {.neighbors = 20}), InputError);
  EXPECT_THROW(StatisticalOutlierInliers(small, {.neighbors = 5}), InputError);
  EXPECT_THROW(KMeans(small, {.clusters = 6}), InputError);
  EXPECT_THROW(KMeans(empty, {}), InputError);
  EXPECT_THROW(RadiusOutlierInliers(small, {.radius_m = 0.0}), OptionsError);
  EXPECT_THROW(EuclideanClusters(small, {.radius_m = 0.0}), OptionsError);
  EXPECT_THROW(VoxelDownsample(small, 0.0), OptionsError);
  EXPECT_THROW(FitPlaneRansac(small, {.distance_threshold_m = 0.0}), OptionsError);
  try {
    EstimateNormals(small, {.neighbors = 20});
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("at least 20 points"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace lidarshop
