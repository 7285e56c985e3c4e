#include "lidarshop/scanner/scanner.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <tuple>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/scanner/builtin_scenes.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/scanner/texture.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

ScannerOptions Scanner(int rows, int cols, double az0, double az1, double el0, double el1,
                       Eigen::Vector3d position = Eigen::Vector3d(0, 0, 2)) {
  ScannerOptions options;
  options.rows = rows;
  options.columns = cols;
  options.azimuth_min_deg = az0;
  options.azimuth_max_deg = az1;
  options.elevation_min_deg = el0;
  options.elevation_max_deg = el1;
  options.position = position;
  return options;
}

TEST(Scanner, PlaneRangesAndNormalsAreAnalytic) {
  for (double yaw : {0.0, 30.0}) {
    ScannerOptions options = Scanner(60, 80, -40, 40, -60, -10);
    options.rotate_deg = Eigen::Vector3d(0, 0, yaw);
    const Scan scan = test_scenes::ScanScene(
        test_scenes::MakeSingleObjectScene(MakePlaneMesh({400, 400}), 7, options), options);
    ASSERT_EQ(scan.CountValid(), scan.num_cells());
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        const cv::Vec3f d = scan.direction.at<cv::Vec3f>(row, col);
        const double expected = -2.0 / d[2];  // the plane z = 0 seen from z = 2 (rotation about z keeps d.z)
        EXPECT_NEAR(scan.range.at<float>(row, col), expected, 1e-5 * expected);
        EXPECT_NEAR(scan.true_range.at<float>(row, col), expected, 1e-5 * expected);
        const cv::Vec3f n = scan.normal.at<cv::Vec3f>(row, col);
        EXPECT_NEAR(n[2], 1.0, 1e-5);
        EXPECT_EQ(scan.label.at<int32_t>(row, col), 7);
        const cv::Vec3f p = scan.point.at<cv::Vec3f>(row, col);
        const Eigen::Vector3f world =
            TransformPoint(scan.world_from_scanner, Eigen::Vector3f(p[0], p[1], p[2]));
        EXPECT_NEAR(world.z(), 0.0, 1e-4);
      }
    }
    // Row 0 is the highest elevation: the nearest ground is at the bottom.
    EXPECT_GT(scan.range.at<float>(0, 40), scan.range.at<float>(59, 40));
  }
}

// Ray from the origin along unit d against the sphere |p - c| = r: the nearer root, or -1.
double RaySphere(const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r, double* discriminant) {
  const double b = d.dot(c);
  *discriminant = b * b - (c.squaredNorm() - r * r);
  if (*discriminant < 0) return -1;
  return b - std::sqrt(*discriminant);
}

TEST(Scanner, SphereRangesAndNormalsAreAnalytic) {
  const Eigen::Vector3d center(1.0, 10.0, 0.5);
  const double radius = 1.5;
  const ScannerOptions options = Scanner(120, 120, -5, 17, -10, 12, Eigen::Vector3d::Zero());
  TriangleMesh sphere = TransformMesh(MakeSphereMesh(radius, 256), ComposeTransform(center, {0, 0, 0}));
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeSingleObjectScene(sphere, 3, options), options);
  int checked = 0, misses = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const Eigen::Vector3d d = Eigen::Vector3f(scan.direction.at<cv::Vec3f>(row, col).val).cast<double>();
      double discriminant = 0;
      const double t = RaySphere(d, center, radius, &discriminant);
      const bool valid = scan.valid.at<uint8_t>(row, col) != 0;
      if (discriminant > 0.05 * radius * radius) {
        ASSERT_TRUE(valid) << row << " " << col;
        // Tessellation error of a 256-segment UV sphere: the facets lie within r (1 - cos²(π/256)) ≈ 2.3e-4 m
        // of the sphere; along the ray that grows by 1 / cos(incidence) = r / sqrt(discriminant).
        EXPECT_NEAR(scan.range.at<float>(row, col), t, 2.5e-4 * radius / std::sqrt(discriminant));
        const Eigen::Vector3d expected_normal = (t * d - center).normalized();
        const Eigen::Vector3d normal =
            Eigen::Vector3f(scan.normal.at<cv::Vec3f>(row, col).val).cast<double>();
        EXPECT_GT(normal.dot(expected_normal), std::cos(0.5 * M_PI / 180)) << row << " " << col;
        EXPECT_EQ(scan.label.at<int32_t>(row, col), 3);
        ++checked;
      } else if (discriminant < -0.05 * radius * radius) {
        EXPECT_FALSE(valid);
        EXPECT_EQ(scan.label.at<int32_t>(row, col), kNoLabel);
        EXPECT_EQ(scan.range.at<float>(row, col), 0.0f);
        ++misses;
      }
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_GT(misses, 1000);
}

TEST(Scanner, TargetAtKnownAnglesLandsInExpectedCell) {
  // Steps of 0.5 degrees; the target sits exactly on the direction of column 70, PTX row 30.
  const ScannerOptions options = Scanner(81, 121, -20, 40, -10, 30, Eigen::Vector3d::Zero());
  const int expected_col = 70, expected_ptx_row = 30;
  const double theta = (-20 + 0.5 * expected_col) * M_PI / 180,
               phi = (-10 + 0.5 * expected_ptx_row) * M_PI / 180;
  const Eigen::Vector3d target = 12.0 * DirectionFromAngles(theta, phi).cast<double>();
  TriangleMesh box = TransformMesh(MakeBoxMesh({0.04, 0.04, 0.04}), ComposeTransform(target, {0, 0, 0}));
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeSingleObjectScene(box, 5, options), options);
  ASSERT_EQ(scan.CountValid(), 1);  // 4 cm at 12 m is narrower than one 0.5-degree step (10 cm)
  const int expected_row = scan.rows - 1 - expected_ptx_row;
  EXPECT_EQ(scan.label.at<int32_t>(expected_row, expected_col), 5);
  EXPECT_NEAR(scan.range.at<float>(expected_row, expected_col), 12.0 - 0.02, 0.03);
}

TEST(Scanner, NoiseStatisticsMatchSigmas) {
  // A wall 10 m ahead filling a 400 x 300 grid: 120,000 noisy returns.
  const double los_sigma = 0.01, orthogonal_sigma = 0.02;
  ScannerOptions options = Scanner(300, 400, -30, 30, -20, 20, Eigen::Vector3d::Zero());
  options.los_noise_sigma_m = los_sigma;
  options.orthogonal_noise_sigma_m = orthogonal_sigma;
  options.seed = 42;
  TriangleMesh wall = TransformMesh(MakePlaneMesh({100, 100}), ComposeTransform({0, 10, 0}, {90, 0, 0}));
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeSingleObjectScene(wall, 1, options), options);
  ASSERT_EQ(scan.CountValid(), 120000);
  double sum_los = 0, sum_los2 = 0, sum_orthogonal2 = 0, sum_b1 = 0, sum_b2 = 0, max_dot = 0;
  int64_t n = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const Eigen::Vector3d d = Eigen::Vector3f(scan.direction.at<cv::Vec3f>(row, col).val).cast<double>();
      const Eigen::Vector3d p = Eigen::Vector3f(scan.point.at<cv::Vec3f>(row, col).val).cast<double>();
      const double along = p.dot(d);
      const double e_los = along - scan.true_range.at<float>(row, col);
      const Eigen::Vector3d orthogonal = p - along * d;
      const Eigen::Vector3d b1 = d.cross(Eigen::Vector3d::UnitZ()).normalized(), b2 = d.cross(b1);
      sum_los += e_los;
      sum_los2 += e_los * e_los;
      sum_orthogonal2 += orthogonal.squaredNorm();
      sum_b1 += std::pow(orthogonal.dot(b1), 2);
      sum_b2 += std::pow(orthogonal.dot(b2), 2);
      max_dot = std::max(max_dot, std::abs(orthogonal.normalized().dot(d)));
      ++n;
    }
  }
  EXPECT_NEAR(sum_los / n, 0.0, 0.05 * los_sigma);
  EXPECT_NEAR(std::sqrt(sum_los2 / n), los_sigma, 0.05 * los_sigma);
  EXPECT_NEAR(std::sqrt(sum_orthogonal2 / n), orthogonal_sigma, 0.05 * orthogonal_sigma);
  // Direction uniform in the perpendicular plane: equal energy along both perpendicular axes.
  EXPECT_NEAR(sum_b1 / sum_b2, 1.0, 0.05);
  (void)max_dot;
  // Orthogonal noise alone does not move the point along its ray (perpendicular,
  // up to float rounding at 10 m).
  options.los_noise_sigma_m = 0;
  const Scan orthogonal_only =
      test_scenes::ScanScene(test_scenes::MakeSingleObjectScene(wall, 1, options), options);
  double max_along = 0, sum_moved2 = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const Eigen::Vector3d d = Eigen::Vector3f(scan.direction.at<cv::Vec3f>(row, col).val).cast<double>();
      const Eigen::Vector3d p =
          Eigen::Vector3f(orthogonal_only.point.at<cv::Vec3f>(row, col).val).cast<double>();
      const double t = orthogonal_only.true_range.at<float>(row, col);
      max_along = std::max(max_along, std::abs(p.dot(d) - t));
      sum_moved2 += (p - t * d).squaredNorm();
    }
  }
  EXPECT_LT(max_along, 1e-5);
  EXPECT_NEAR(std::sqrt(sum_moved2 / n), orthogonal_sigma, 0.05 * orthogonal_sigma);
}

TEST(Scanner, IdenticalWhateverTheThreadCount) {
  test_scenes::GroundAndBoxOptions box_options;
  box_options.los_noise_sigma = 0.01;
  box_options.orthogonal_noise_sigma = 0.005;
  const SceneDescription scene = test_scenes::MakeGroundAndBoxScene(box_options);
  Scan one, two;
  {
    ThreadLimit limit(1);
    one = test_scenes::ScanScene(scene);
  }
  {
    ThreadLimit limit(2);
    two = test_scenes::ScanScene(scene);
  }
  ASSERT_GT(one.CountValid(), 1000);
  for (auto [a, b] : {std::pair{one.point, two.point},
                      {one.range, two.range},
                      {one.color, two.color},
                      {one.intensity, two.intensity},
                      {one.label, two.label},
                      {one.normal, two.normal}}) {
    cv::Mat diff;
    cv::absdiff(a.reshape(1), b.reshape(1), diff);
    EXPECT_EQ(cv::countNonZero(diff), 0);
  }
  // Another seed gives other noise.
  SceneDescription other = scene;
  other.scanner.seed = 2;
  const Scan three = test_scenes::ScanScene(other);
  cv::Mat diff;
  cv::absdiff(one.range, three.range, diff);
  EXPECT_GT(cv::countNonZero(diff), one.CountValid() / 2);
}

TEST(Scanner, ColourIntensityAndLabelsOfTheGroundAndBoxScene) {
  test_scenes::GroundAndBoxOptions box_options;
  box_options.ground_texture = false;
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene(box_options));
  std::set<int32_t> labels;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const int32_t label = scan.label.at<int32_t>(row, col);
      labels.insert(label);
      if (label == 1) {
        EXPECT_EQ(scan.color.at<cv::Vec3b>(row, col), cv::Vec3b(200, 50, 40));
      }
      if (label == 0) EXPECT_EQ(scan.color.at<cv::Vec3b>(row, col), cv::Vec3b(128, 128, 128));
      const float intensity = scan.intensity.at<float>(row, col);
      if (label != kNoLabel) {
        EXPECT_GE(intensity, 0.0f);
        EXPECT_LE(intensity, 1.0f);
      }
    }
  }
  EXPECT_EQ(labels, (std::set<int32_t>{kNoLabel, 0, 1}));
  // Intensity falls with the incidence angle: the ground far away (grazing) is darker than the ground below.
  EXPECT_LT(scan.intensity.at<float>(scan.rows / 2 + 10, 5), scan.intensity.at<float>(scan.rows - 1, 5));
}

TEST(Scanner, TexturesAreDeterministicAndVaried) {
  const SceneDescription scene = test_scenes::MakeGroundAndBoxScene();
  const Scan a = test_scenes::ScanScene(scene), b = test_scenes::ScanScene(scene);
  cv::Mat diff;
  cv::absdiff(a.color.reshape(1), b.color.reshape(1), diff);
  EXPECT_EQ(cv::countNonZero(diff), 0);
  // Grass is not a flat colour.
  std::set<int> greens;
  for (int col = 0; col < a.cols; ++col) greens.insert(a.color.at<cv::Vec3b>(a.rows - 1, col)[1]);
  EXPECT_GT(greens.size(), 20u);
}

TEST(Scanner, FusedPacketPathMatchesTheSingleRayPath) {
  test_scenes::GroundAndBoxOptions box_options;
  box_options.los_noise_sigma = 0.01;
  box_options.orthogonal_noise_sigma = 0.005;
  SceneDescription scene = test_scenes::MakeGroundAndBoxScene(box_options);
  ASSERT_EQ(scene.scanner.cast_method, CastMethod::kPacket16);  // the fused cast-and-shade loop
  const Scan fused = test_scenes::ScanScene(scene);
  scene.scanner.cast_method = CastMethod::kSingle;  // cast into hit images, then shade
  const Scan single = test_scenes::ScanScene(scene);
  ASSERT_GT(fused.CountValid(), 1000);
  int64_t label_mismatches = 0, compared = 0;
  for (int row = 0; row < fused.rows; ++row) {
    for (int col = 0; col < fused.cols; ++col) {
      const int32_t label = fused.label.at<int32_t>(row, col);
      if (label != single.label.at<int32_t>(row, col)) {
        ++label_mismatches;
        continue;
      }
      if (label == kNoLabel) continue;
      ++compared;
      EXPECT_NEAR(fused.range.at<float>(row, col), single.range.at<float>(row, col), 1e-4f);
      EXPECT_NEAR(fused.intensity.at<float>(row, col), single.intensity.at<float>(row, col), 1e-4f);
      EXPECT_NEAR(cv::norm(fused.normal.at<cv::Vec3f>(row, col) - single.normal.at<cv::Vec3f>(row, col)), 0.0,
                  1e-4);
    }
  }
  EXPECT_LE(label_mismatches, fused.num_cells() / 1000);  // only rays through a shared edge may differ
  EXPECT_GT(compared, 1000);
}

// The two SIMD paths of the shading (scanner/shade.h) give the same scan, bit for bit: the
// parking lot with noise, procedural textures and curved (per-cell) car bodies, on a grid whose
// rows and columns are not multiples of the band (4) and of the SIMD width (8). On a CPU without
// AVX2 both runs take the baseline path.
TEST(Scanner, BaselineAndAvx2ShadingGiveIdenticalScans) {
  SceneDescription scene = LoadScene(LIDARSHOP_SOURCE_DIR "/data/scenes/parking_lot.json");
  scene.scanner.rows = 237;
  scene.scanner.columns = 301;
  ASSERT_GT(scene.scanner.los_noise_sigma_m, 0.0);
  const SyntheticScanner scanner(scene);
  ScannerOptions options = scene.scanner;
  options.simd_path = SimdPath::kScalar;
  const Scan baseline = scanner.Acquire(options);
  options.simd_path = SimdPath::kAvx2;
  const Scan avx2 = scanner.Acquire(options);
  ASSERT_GT(baseline.CountValid(), baseline.num_cells() / 2);
  for (const auto& [name, a, b] : {std::tuple{"valid", baseline.valid, avx2.valid},
                                   {"range", baseline.range, avx2.range},
                                   {"point", baseline.point, avx2.point},
                                   {"intensity", baseline.intensity, avx2.intensity},
                                   {"color", baseline.color, avx2.color},
                                   {"label", baseline.label, avx2.label},
                                   {"normal", baseline.normal, avx2.normal},
                                   {"true_range", baseline.true_range, avx2.true_range},
                                   {"direction", baseline.direction, avx2.direction}}) {
    SCOPED_TRACE(name);
    ASSERT_EQ(a.total() * a.elemSize(), b.total() * b.elemSize());
    EXPECT_EQ(std::memcmp(a.data, b.data, a.total() * a.elemSize()), 0);
  }
  // The scan has what the comparison is meant to cover: textured ground, several objects, noise.
  std::set<int32_t> labels;
  for (int row = 0; row < avx2.rows; ++row) {
    for (int col = 0; col < avx2.cols; ++col) labels.insert(avx2.label.at<int32_t>(row, col));
  }
  EXPECT_GE(labels.size(), 5u);
}

// Grids smaller than a band (4 rows) or a SIMD step (8 columns; the smallest grid is 2 x 2), and ragged ones:
// every cell is shaded, the two SIMD paths agree, and the hits are those of one ray at a time.
TEST(Scanner, SmallAndRaggedGridsShadeEveryCell) {
  test_scenes::GroundAndBoxOptions box_options;
  box_options.los_noise_sigma = 0.01;
  box_options.orthogonal_noise_sigma = 0.005;
  const SceneDescription scene = test_scenes::MakeGroundAndBoxScene(box_options);
  const SyntheticScanner scanner(scene);
  for (const auto& [rows, cols] : {std::pair{2, 2}, {2, 9}, {3, 5}, {5, 17}, {4, 8}, {9, 23}}) {
    SCOPED_TRACE(::testing::Message() << rows << " x " << cols);
    ScannerOptions options = scene.scanner;
    options.rows = rows;
    options.columns = cols;
    options.elevation_max_deg = -5;  // every ray meets the ground or the box
    options.simd_path = SimdPath::kScalar;
    const Scan baseline = scanner.Acquire(options);
    options.simd_path = SimdPath::kAvx2;
    const Scan avx2 = scanner.Acquire(options);
    options.cast_method = CastMethod::kSingle;
    const Scan single = scanner.Acquire(options);
    EXPECT_EQ(baseline.CountValid(), rows * cols);
    for (const auto& [a, b] : {std::pair{baseline.point, avx2.point},
                               {baseline.color, avx2.color},
                               {baseline.intensity, avx2.intensity},
                               {baseline.label, avx2.label},
                               {baseline.normal, avx2.normal},
                               {baseline.direction, avx2.direction}}) {
      EXPECT_EQ(std::memcmp(a.data, b.data, a.total() * a.elemSize()), 0);
    }
    for (int row = 0; row < rows; ++row) {
      for (int col = 0; col < cols; ++col) {
        EXPECT_EQ(avx2.label.at<int32_t>(row, col), single.label.at<int32_t>(row, col));
        EXPECT_NEAR(avx2.true_range.at<float>(row, col), single.true_range.at<float>(row, col), 1e-4f);
        EXPECT_GT(avx2.range.at<float>(row, col), 0.0f);
      }
    }
  }
}

// Per-cell colours: an image texture on one half of a wall, vertex colours on the other; groups of 8 cells
// that straddle the two objects take each lane from its own object.
TEST(Scanner, ImageTexturesAndVertexColoursColourEachReturn) {
  auto quad = [](float x0, float x1) {
    TriangleMesh mesh;
    mesh.vertices = {{x0, 5, 0}, {x1, 5, 0}, {x1, 5, 3}, {x0, 5, 3}};
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    return mesh;
  };
  SceneDescription scene;
  scene.scanner = Scanner(60, 90, -30, 30, -20, 20, Eigen::Vector3d(0, 0, 1.5));
  SceneObject textured;
  textured.mesh = quad(-2, 0);
  textured.mesh.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // s = (x + 2) / 2
  textured.mesh.triangle_texcoords = textured.mesh.triangles;
  textured.mesh.texture = cv::Mat(1, 2, CV_8UC3);
  textured.mesh.texture.at<cv::Vec3b>(0, 0) = cv::Vec3b(255, 0, 0);  // RGB: red left, green right
  textured.mesh.texture.at<cv::Vec3b>(0, 1) = cv::Vec3b(0, 255, 0);
  textured.label = 1;
  SceneObject painted;
  painted.mesh = quad(0, 2);
  painted.mesh.vertex_colors.assign(4, Rgb8(20, 40, 200));
  painted.label = 2;
  scene.objects = {textured, painted};
  const SyntheticScanner scanner(scene);
  int red = 0, green = 0, blue = 0;
  for (const SimdPath path : {SimdPath::kScalar, SimdPath::kAvx2}) {
    ScannerOptions options = scene.scanner;
    options.simd_path = path;
    const Scan scan = scanner.Acquire(options);
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        const int32_t label = scan.label.at<int32_t>(row, col);
        const float x = scan.point.at<cv::Vec3f>(row, col)[0];
        const cv::Vec3b color = scan.color.at<cv::Vec3b>(row, col);
        if (label == 1 && x < -1.05f) {
          EXPECT_EQ(color, cv::Vec3b(255, 0, 0)) << row << " " << col;
          ++red;
        } else if (label == 1 && x > -0.95f && x < -0.05f) {
          EXPECT_EQ(color, cv::Vec3b(0, 255, 0)) << row << " " << col;
          ++green;
        } else if (label == 2) {
          EXPECT_EQ(color, cv::Vec3b(20, 40, 200)) << row << " " << col;
          ++blue;
        }
      }
    }
  }
  EXPECT_GT(red, 200);
  EXPECT_GT(green, 200);
  EXPECT_GT(blue, 400);
}

TEST(Texture, BatchPathsAgreeWithEachOtherAndWithSinglePoints) {
  std::vector<float> u, v, footprint;
  std::vector<uint32_t> base;
  for (int i = 0; i < 1003; ++i) {  // not a multiple of 8: the last group is partial
    u.push_back(-7.3f + 0.0137f * i);
    v.push_back(2.1f - 0.0093f * i);
    footprint.push_back(0.0002f * (i % 300));
    base.push_back(PackRgb(Rgb8(40 + i % 200, 90, 160 - i % 100)));
  }
  const int count = static_cast<int>(u.size());
  for (TextureKind kind :
       {TextureKind::kChecker, TextureKind::kGrass, TextureKind::kGravel, TextureKind::kBrick}) {
    SCOPED_TRACE(ToString(kind));
    std::vector<uint32_t> baseline(u.size()), avx2(u.size());
    EvaluateTextures(kind, 1.3f, count, u.data(), v.data(), footprint.data(), base.data(), baseline.data(),
                     SimdPath::kScalar);
    EvaluateTextures(kind, 1.3f, count, u.data(), v.data(), footprint.data(), base.data(), avx2.data(),
                     SimdPath::kAvx2);
    EXPECT_EQ(baseline, avx2);
    std::set<uint32_t> distinct(baseline.begin(), baseline.end());
    EXPECT_GT(distinct.size(), 10u);
    for (int i = 0; i < count; i += 97) {
      EXPECT_EQ(PackRgb(EvaluateTexture(kind, u[i], v[i], UnpackRgb(base[i]), 1.3f, footprint[i])),
                baseline[i]);
    }
  }
}

// Std and mean (green channel) of a texture sampled on a 0.1 m grid (coarser than its fine detail).
std::pair<double, double> SampledGreen(TextureKind kind, float footprint_m) {
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int i = 0; i < 200; ++i) {
    for (int j = 0; j < 200; ++j) {
      const float g =
          EvaluateTexture(kind, 0.1037f * i, 0.0991f * j, DefaultTextureColor(kind), 1.0f, footprint_m)[1];
      sum += g;
      sum2 += g * g;
      ++n;
    }
  }
  const double mean = sum / n;
  return {std::sqrt(sum2 / n - mean * mean), mean};
}

TEST(Texture, FootprintFilteringRemovesSubSampleDetailAndKeepsTheMean) {
  for (TextureKind kind : {TextureKind::kGrass, TextureKind::kGravel, TextureKind::kBrick}) {
    const auto [point_std, point_mean] = SampledGreen(kind, 0.0f);
    const auto [filtered_std, filtered_mean] = SampledGreen(kind, 0.1f);
    SCOPED_TRACE(ToString(kind));
    EXPECT_GT(point_std, 5.0);                    // point sampling shows the (aliased) detail
    EXPECT_LT(filtered_std, 0.5 * point_std);     // the footprint removes it
    EXPECT_NEAR(filtered_mean, point_mean, 4.0);  // ... and keeps the average colour
  }
  // Detail coarser than the footprint stays: 1 m checker squares under a 0.1 m footprint.
  EXPECT_EQ(EvaluateTexture(TextureKind::kChecker, 0.5f, 0.5f, Rgb8(200, 200, 200), 1.0f, 0.1f),
            Rgb8(200, 200, 200));
  EXPECT_EQ(EvaluateTexture(TextureKind::kChecker, 1.5f, 0.5f, Rgb8(200, 200, 200), 1.0f, 0.1f),
            Rgb8(60, 60, 60));
}

TEST(Scanner, DistantTexturedGroundDoesNotAlias) {
  test_scenes::GroundAndBoxOptions box_options;
  box_options.box_center = Eigen::Vector3d(0, -50, 0.5);  // out of view: only ground
  SceneDescription scene = test_scenes::MakeGroundAndBoxScene(box_options);
  for (auto& object : scene.objects) object.material.texture = TextureKind::kGravel;
  // Mean absolute colour step between horizontal neighbours over the ground rows beyond 10 m.
  auto roughness = [&](bool filter) {
    scene.scanner.filter_textures = filter;
    const Scan scan = test_scenes::ScanScene(scene);
    double sum = 0;
    int64_t n = 0;
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 1; col < scan.cols; ++col) {
        if (scan.label.at<int32_t>(row, col) != 0 || scan.label.at<int32_t>(row, col - 1) != 0) continue;
        if (scan.true_range.at<float>(row, col) < 10.0f) continue;
        sum += std::abs(scan.color.at<cv::Vec3b>(row, col)[1] - scan.color.at<cv::Vec3b>(row, col - 1)[1]);
        ++n;
      }
    }
    EXPECT_GT(n, 1000);
    return sum / std::max<int64_t>(n, 1);
  };
  const double aliased = roughness(false), filtered = roughness(true);
  EXPECT_GT(aliased, 10.0);
  EXPECT_LT(filtered, 0.2 * aliased);
}

std::string WriteTemporary(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

void ExpectInputError(const std::string& path, const std::vector<std::string>& parts) {
  try {
    LoadScene(path);
    FAIL() << "no error for " << path;
  } catch (const InputError& error) {
    for (const auto& part : parts)
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
  }
}

TEST(SceneFile, ErrorsNameTheFileAndTheField) {
  ExpectInputError(
      WriteTemporary("scanner_test_bad_key.json",
                     R"({"objects": [{"primitive": "sphere", "radius": 1, "colour": [1, 2, 3]}]})"),
      {"scanner_test_bad_key.json", "objects[0]", "'colour'", "unknown key"});
  ExpectInputError(WriteTemporary("scanner_test_bad_type.json",
                                  R"({"objects": [{"primitive": "sphere", "radius": "big"}]})"),
                   {"scanner_test_bad_type.json", "objects[0]", "'radius'", "expected a number"});
  ExpectInputError(
      WriteTemporary("scanner_test_no_mesh.json", R"({"objects": [{"mesh": "meshes/missing.obj"}]})"),
      {"scanner_test_no_mesh.json", "objects[0]", "'mesh'", "missing.obj"});
  ExpectInputError(
      WriteTemporary("scanner_test_bad_scanner.json", R"({"scanner": {"rows": 0}, "objects": []})"),
      {"scanner_test_bad_scanner.json", "scanner", "'rows'"});
  ExpectInputError(WriteTemporary("scanner_test_bad_json.json", R"({"objects": [)"),
                   {"scanner_test_bad_json.json", "byte", "not valid JSON"});
  ExpectInputError(WriteTemporary("scanner_test_bad_texture.json",
                                  R"({"objects": [{"primitive": "plane", "texture": "marble"}]})"),
                   {"scanner_test_bad_texture.json", "'texture'", "marble"});
  ExpectInputError(
      WriteTemporary("scanner_test_bad_primitive.json", R"({"objects": [{"primitive": "torus"}]})"),
      {"'primitive'", "torus"});
  ExpectInputError("/nonexistent/scene.json", {"/nonexistent/scene.json", "cannot open"});
}

TEST(SceneFile, AMeshNameTooLongForTheSystemIsNotFound) {
  // The system refuses names past NAME_MAX with an error, not "no": that is a missing mesh, not a crash.
  const std::string text = fmt::format(R"({{"objects": [{{"mesh": "{}.obj"}}]}})", std::string(5000, 'x'));
  try {
    ParseScene(text, "long.json", ".");
    ADD_FAILURE() << "a mesh name of 5,004 characters was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), testing::HasSubstr("mesh file not found"));
    EXPECT_THAT(error.what(), testing::HasSubstr("'mesh'"));
  }
}

TEST(SceneFile, TheIssueExampleParses) {
  const std::string text = R"({"scanner": {"position": [0, 0, 1.5], "rotate_deg": [0, 0, 0],
     "azimuth_deg": [-45, 45], "elevation_deg": [-30, 30], "columns": 900, "rows": 600,
     "max_range": 100, "los_noise_sigma": 0.0, "orthogonal_noise_sigma": 0.0, "seed": 1},
   "objects": [
     {"primitive": "plane", "size": [200, 200], "translate": [0, 0, 0], "label": 0, "texture": "grass"},
     {"primitive": "sphere", "radius": 1.0, "translate": [2, 10, 1], "label": 1, "color": [200, 40, 40]},
     {"primitive": "box", "size": [1, 0.6, 1.2], "translate": [-2, 8, 0.6], "label": 2},
     {"primitive": "cylinder", "radius": 0.1, "height": 3, "translate": [4, 12, 1.5], "label": 3},
     {"primitive": "cone", "radius": 0.5, "height": 1, "scale": [1, 1, 2], "rotate_deg": [0, 0, 30],
      "translate": [-4, 12, 1], "label": 4}]})";
  const SceneDescription scene = ParseScene(text, "example.json", ".");
  ASSERT_EQ(scene.objects.size(), 5u);
  EXPECT_EQ(scene.scanner.columns, 900);
  EXPECT_EQ(scene.objects[1].material.color, Rgb8(200, 40, 40));
  EXPECT_EQ(scene.objects[0].material.texture, TextureKind::kGrass);
  EXPECT_NEAR(scene.objects[4].world_from_object(2, 2), 2.0, 1e-12);  // z scaled by 2, rotated about z
  const Scan scan = test_scenes::ScanScene(scene, test_scenes::SmallScanner(scene.scanner, 150, 225));
  std::set<int32_t> labels(scan.label.begin<int32_t>(), scan.label.end<int32_t>());
  EXPECT_EQ(labels, (std::set<int32_t>{kNoLabel, 0, 1, 2, 3, 4}));
}

TEST(SceneFile, BuiltinScenesLoadAndShowEveryObject) {
  for (const std::string name : {"parking_lot", "electric_box", "mailbox"}) {
    const SceneDescription scene = test_scenes::LoadBuiltinScene(name);
    EXPECT_LE(scene.scanner.rows * scene.scanner.columns, 1000 * 600) << name;
    const Scan scan = test_scenes::ScanScene(scene, test_scenes::SmallScanner(scene.scanner, 280, 480));
    std::set<int32_t> seen(scan.label.begin<int32_t>(), scan.label.end<int32_t>());
    for (const auto& object : scene.objects)
      EXPECT_TRUE(seen.contains(object.label)) << name << " " << object.name;
  }
}

TEST(SceneFile, ABuiltinSceneByNameOrElseAFile) {
  EXPECT_EQ(LoadSceneOrBuiltin("mailbox").demo.cut_object, "mailbox");
  EXPECT_EQ(FindBuiltinScene("no_such_scene"), nullptr);
  try {
    LoadSceneOrBuiltin("no_such_scene");
    ADD_FAILURE() << "an unknown name was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), testing::HasSubstr("'no_such_scene' is neither a built-in scene"));
    EXPECT_THAT(error.what(), testing::HasSubstr("parking_lot"));
  }
}

TEST(SceneFile, TheDemoKeyNamesObjectsTheSceneHas) {
  const SceneDescription parking_lot = test_scenes::LoadBuiltinScene("parking_lot");
  EXPECT_EQ(parking_lot.demo.cut_object, "hatchback");
  EXPECT_EQ(parking_lot.demo.sweep_object, "sedan");
  EXPECT_EQ(parking_lot.demo.site, "parking_lot_stations");
  EXPECT_NE(parking_lot.demo.sweep_options_json.find("\"step_m\":0.5"), std::string::npos);
  EXPECT_TRUE(test_scenes::LoadBuiltinScene("mailbox").demo.sweep_object.empty());
  const std::string objects = R"("objects": [{"name": "post", "primitive": "cylinder", "radius": 0.1}])";
  ExpectInputError(
      WriteTemporary("scanner_test_demo_cut.json", "{" + objects + R"(, "demo": {"cut": "car"}})"),
      {"scanner_test_demo_cut.json", "demo", "'cut'", "no object named 'car'"});
  ExpectInputError(
      WriteTemporary("scanner_test_demo_key.json", "{" + objects + R"(, "demo": {"cutout": "post"}})"),
      {"demo", "'cutout'", "unknown key"});
  ExpectInputError(WriteTemporary("scanner_test_demo_sweep.json",
                                  "{" + objects + R"(, "demo": {"sweep": {"options": {"step_m": 1}}}})"),
                   {"demo.sweep", "'object'", "missing"});
}

TEST(Primitives, CarsHaveRealSizesAndCanBeRefined) {
  for (auto [style, length] :
       {std::pair{CarStyle::kSedan, 4.6}, {CarStyle::kHatchback, 4.0}, {CarStyle::kVan, 4.9}}) {
    CarMeshOptions options;
    options.style = style;
    const TriangleMesh car = MakeCarMesh(options);
    const Eigen::AlignedBox3f box = Bounds(car);
    EXPECT_NEAR(box.sizes().y(), length, 0.25);
    EXPECT_NEAR(box.min().z(), 0.0, 1e-4);
    EXPECT_GT(box.sizes().z(), 1.3);
    EXPECT_EQ(car.triangle_colors.size(), car.triangles.size());
  }
  CarMeshOptions fine;
  fine.subdivisions = 4;
  const TriangleMesh car = MakeCarMesh(fine);
  EXPECT_GE(car.triangles.size(), 200000u);
  EXPECT_NEAR(SurfaceArea(car), SurfaceArea(MakeCarMesh(CarMeshOptions())), 1e-3 * SurfaceArea(car));
}

TEST(Primitives, FacadeFrontHasOneHolePerOpening) {
  // The front face (y = 0) is the slab minus every window (1.5 m wide, at most 1.7 m high) and the door
  // (1.3 x 2.3 m): its area tells whether each opening was cut once, and only there.
  auto front_area = [](const TriangleMesh& mesh) {
    double area = 0;
    for (const auto& t : mesh.triangles) {
      const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                            c = mesh.vertices[t[2]].cast<double>();
      if (a.y() == 0 && b.y() == 0 && c.y() == 0) area += (b - a).cross(c - a).norm() / 2;
    }
    return area;
  };
  FacadeMeshOptions small;  // 20 x 9 m, 3 floors of 6: windows 1.5 x 1.5 m
  EXPECT_NEAR(front_area(MakeFacadeMesh(small)), 20.0 * 9.0 - 17 * 1.5 * 1.5 - 1.3 * 2.3, 1e-3);
  FacadeMeshOptions tall;  // 15,000 openings: cut in well under a second, not minutes
  tall.width = 1000;
  tall.height = 400;
  tall.floors = 100;
  tall.windows_per_floor = 150;
  EXPECT_NEAR(front_area(MakeFacadeMesh(tall)), 1000.0 * 400.0 - 14999 * 1.5 * 1.7 - 1.3 * 2.3, 1.0);
}

TEST(Primitives, ClosedPrimitivesHaveConsistentOutwardWinding) {
  // For a closed mesh with outward counter-clockwise faces, the divergence theorem gives the positive volume.
  auto volume = [](const TriangleMesh& mesh) {
    double v = 0;
    for (const auto& t : mesh.triangles) {
      v += mesh.vertices[t[0]].cast<double>().dot(
               mesh.vertices[t[1]].cast<double>().cross(mesh.vertices[t[2]].cast<double>())) /
           6;
    }
    return v;
  };
  EXPECT_NEAR(volume(MakeBoxMesh({1, 2, 3})), 6.0, 1e-5);
  EXPECT_NEAR(volume(MakeSphereMesh(1.0, 256)), 4.0 / 3 * M_PI, 2e-3);
  EXPECT_NEAR(volume(MakeCylinderMesh(0.5, 2, 256)), M_PI * 0.25 * 2, 2e-3);
  EXPECT_NEAR(volume(MakeConeMesh(0.5, 3, 256)), M_PI * 0.25 * 3 / 3, 2e-3);
}

}  // namespace
}  // namespace lidarshop
