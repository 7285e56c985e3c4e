#include "lidarshop/recolor/align.h"

#include <random>

#include <gtest/gtest.h>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/geometry/transform.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

TEST(Align, LandmarksGiveTheRigidAndTheScaledTransform) {
  const Eigen::Matrix4d truth = ComposeTransform({3, -1, 0.5}, {5, -10, 40});
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> unit(-5, 5);
  std::vector<PointPair> pairs;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d source(unit(rng), unit(rng), unit(rng));
    pairs.push_back({source, (truth * source.homogeneous()).head<3>()});
  }
  const LandmarkAlignment rigid = AlignLandmarks(pairs, false, "c");
  EXPECT_LT((rigid.target_from_source - truth).norm(), 1e-9);
  EXPECT_LT(rigid.rms_m, 1e-9);
  for (PointPair& pair : pairs) pair.target *= 2.0;
  const LandmarkAlignment scaled = AlignLandmarks(pairs, true, "c");
  EXPECT_NEAR(scaled.scale, 2.0, 1e-9);
  EXPECT_LT(scaled.rms_m, 1e-9);
  EXPECT_GT(AlignLandmarks(pairs, false, "c").rms_m, 0.1);  // a rigid fit cannot explain the scale
  EXPECT_THROW(AlignLandmarks(std::span(pairs).first(2), false, "c"), InputError);
  std::vector<PointPair> line = {{{0, 0, 0}, {0, 0, 0}}, {{1, 0, 0}, {1, 0, 0}}, {{2, 0, 0}, {2, 0, 0}}};
  EXPECT_THROW(AlignLandmarks(line, false, "c"), InputError);
}

TEST(Align, PhotoPairsGiveTheHomographyAndTheFundamentalMatrix) {
  Eigen::Matrix3d h;
  h << 1.1, 0.05, 12, -0.02, 0.95, -7, 1e-4, -5e-5, 1;
  std::vector<PixelPair> pairs;
  for (int i = 0; i < 30; ++i) {
    const Eigen::Vector2d a(17.0 + 31 * (i % 6), 9.0 + 47 * (i / 6));
    pairs.push_back({a, (h * a.homogeneous()).hnormalized()});
  }
  pairs[3].pixel_b += Eigen::Vector2d(40, -25);  // an outlier
  const PhotoPairModel homography = EstimateHomography(pairs, 2.0, "c");
  EXPECT_LT((homography.matrix / homography.matrix(2, 2) - h).norm(), 1e-4);
  EXPECT_EQ(homography.inlier[3], 0);
  EXPECT_LT(homography.rms_px, 1e-4);

  // Two cameras looking at points in depth: b^T F a = 0.
  const PinholeCamera left = CameraLookingAt({0, 0, 1.5}, {0, 10, 1.5}, 640, 480, 60);
  const PinholeCamera right = CameraLookingAt({1, 0.2, 1.6}, {0, 10, 1.4}, 640, 480, 60);
  std::vector<PixelPair> stereo;
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d point(-3 + 6 * unit(rng), 5 + 10 * unit(rng), 3 * unit(rng));
    PixelPair pair;
    ASSERT_TRUE(ProjectWorldPoint(left, point, &pair.pixel_a));
    ASSERT_TRUE(ProjectWorldPoint(right, point, &pair.pixel_b));
    stereo.push_back(pair);
  }
  const PhotoPairModel fundamental = EstimateFundamental(stereo, 1.0, "c");
  EXPECT_LT(fundamental.rms_px, 0.01);
  EXPECT_THROW(EstimateFundamental(std::span(stereo).first(7), 1.0, "c"), InputError);
}

TEST(Correspondences, ParsesEveryKindAndNamesTheBrokenField) {
  const Correspondences pixel_point = ParseCorrespondences(
      R"({"image_size_px": [640, 480], "pairs": [{"pixel": [1.5, 2.5], "point": [1, 2, 3]}]})", "c.json");
  EXPECT_EQ(pixel_point.kind, PairKind::kPixelPoint);
  EXPECT_EQ(pixel_point.width_px, 640);
  EXPECT_EQ(pixel_point.pixel_point[0].pixel_px, Eigen::Vector2d(1.5, 2.5));
  EXPECT_EQ(pixel_point.pixel_point[0].point_in_world, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(ParseCorrespondences(R"({"pairs": [{"source": [0, 0, 0], "target": [1, 1, 1]}]})", "c").kind,
            PairKind::kLandmark);
  EXPECT_EQ(ParseCorrespondences(R"({"pairs": [{"pixel_a": [0, 0], "pixel_b": [1, 1]}]})", "c").kind,
            PairKind::kPixelPixel);
  const auto message = [](const std::string& text, const Scan* scan = nullptr) -> std::string {
    try {
      ParseCorrespondences(text, "c.json", scan);
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  };
  EXPECT_EQ(message(R"({"pairs": [{"pixel": [1, 2]}]})"), "c.json: pairs[0]: field 'point': missing");
  EXPECT_EQ(message(R"({"pairs": [{"pixel": [1, null], "point": [1, 2, 3]}]})"),
            "c.json: pairs[0]: field 'pixel': expected 2 numbers");
  EXPECT_NE(message(R"({"pairs": [{"pixel": [1, NaN], "point": [1, 2, 3]}]})").find("c.json: not valid JSON"),
            std::string::npos);
  EXPECT_NE(message(R"({"pairs": [{"pixel": [1, 1e999], "point": [1, 2, 3]}]})").find("c.json: "),
            std::string::npos);  // overflow: refused by the JSON parser
  EXPECT_NE(message(R"({"pairs": [{"pixel": [1, 2], "cell": [0, 0]}]})").find("--scan"), std::string::npos);
  EXPECT_NE(
      message(R"({"pairs": [{"pixel": [1, 2], "point": [1, 2, 3]}, {"pixel_a": [0, 0], "pixel_b": [1, 1]}]})")
          .find("pairs[1]"),
      std::string::npos);
  Scan scan = MakeScan(2, 3);
  scan.valid.at<uint8_t>(1, 2) = kValid;
  scan.point.at<cv::Vec3f>(1, 2) = cv::Vec3f(1, 2, 3);
  scan.world_from_scanner(0, 3) = 10;
  const Correspondences cells =
      ParseCorrespondences(R"({"pairs": [{"pixel": [1, 2], "cell": [1, 2]}]})", "c", &scan);
  EXPECT_EQ(cells.pixel_point[0].point_in_world, Eigen::Vector3d(11, 2, 3));
  EXPECT_NE(message(R"({"pairs": [{"pixel": [1, 2], "cell": [0, 0]}]})", &scan).find("no return"),
            std::string::npos);
  EXPECT_NE(message(R"({"pairs": [{"pixel": [1, 2], "cell": [2, 0]}]})", &scan).find("not a cell"),
            std::string::npos);
}

}  // namespace
}  // namespace lidarshop
