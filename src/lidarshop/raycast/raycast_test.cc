#include "lidarshop/raycast/raycast.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// A 20 x 20 m plane at z = 0 (id 3) and a sphere of radius 1 at (0, 10, 2) (id 8).
RaycastScene MakeScene(bool robust = true) {
  RaycastSceneOptions options;
  options.robust = robust;
  RaycastScene scene(options);
  scene.AddMesh(MakePlaneMesh({20, 20}), 3);
  scene.AddMesh(TransformMesh(MakeSphereMesh(1.0, 256), ComposeTransform({0, 10, 2}, {0, 0, 0})), 8);
  scene.Commit();
  return scene;
}

TEST(Raycast, PlaneHitsAreAnalytic) {
  const RaycastScene scene = MakeScene();
  std::vector<Ray> rays;
  for (int i = 0; i < 50; ++i) {
    Ray ray;
    ray.origin = Eigen::Vector3f(0.1f * i - 2, -3, 5);
    ray.direction = Eigen::Vector3f(0.01f * i, 0.2f, -1.0f).normalized();
    rays.push_back(ray);
  }
  std::vector<RayHit> hits(rays.size());
  scene.Cast(rays, hits);
  for (size_t i = 0; i < rays.size(); ++i) {
    ASSERT_TRUE(hits[i].hit());
    EXPECT_EQ(hits[i].geometry_id, 3);
    EXPECT_NEAR(hits[i].t_hit, 5.0f / -rays[i].direction.z(), 1e-4);
    EXPECT_NEAR(hits[i].normal.z(), 1.0f, 1e-6);  // the plane's winding faces +z
    const Eigen::Vector3f p = rays[i].origin + hits[i].t_hit * rays[i].direction;
    EXPECT_NEAR(p.z(), 0.0f, 1e-4);
  }
}

TEST(Raycast, SphereHitsAreAnalyticAndMissesAreMarked) {
  const RaycastScene scene = MakeScene();
  const Eigen::Vector3f origin(0, 0, 2), center(0, 10, 2);
  std::vector<Ray> rays;
  for (int i = -20; i <= 20; ++i) {
    Ray ray;
    ray.origin = origin;
    ray.direction = Eigen::Vector3f(0.01f * i, 1.0f, 0.0f).normalized();
    rays.push_back(ray);
  }
  Ray up;
  up.origin = origin;
  up.direction = Eigen::Vector3f::UnitZ();
  rays.push_back(up);
  std::vector<RayHit> hits(rays.size());
  scene.CastSerial(rays, hits);
  for (size_t i = 0; i + 1 < rays.size(); ++i) {
    const Eigen::Vector3f d = rays[i].direction;
    const float b = d.dot(center - origin);
    const float discriminant = b * b - ((center - origin).squaredNorm() - 1.0f);
    if (discriminant < 0.05f) continue;
    ASSERT_TRUE(hits[i].hit()) << i;
    EXPECT_EQ(hits[i].geometry_id, 8);
    EXPECT_GE(hits[i].primitive_id, 0);
    const float t = b - std::sqrt(discriminant);
    EXPECT_NEAR(hits[i].t_hit, t, 2.5e-4f / std::sqrt(discriminant));
    const Eigen::Vector3f expected_normal = (origin + t * d - center).normalized();
    EXPECT_GT(hits[i].normal.dot(expected_normal),
              std::cos(1.0 * M_PI / 180));  // facet normal within 1 degree
    const Eigen::Vector3f p = origin + hits[i].t_hit * d;
    EXPECT_NEAR((p - center).norm(), 1.0f, 3e-4f);
  }
  EXPECT_FALSE(hits.back().hit());
  EXPECT_EQ(hits.back().geometry_id, kInvalidId);
  EXPECT_TRUE(std::isinf(hits.back().t_hit));
}

TEST(Raycast, OccludedMatchesSegments) {
  const RaycastScene scene = MakeScene();
  std::vector<Ray> rays(3);
  rays[0].origin = Eigen::Vector3f(0, 0, 2);
  rays[0].direction = Eigen::Vector3f::UnitY();
  rays[0].t_far = 8.5f;  // stops before the sphere (front at y = 9)
  rays[1] = rays[0];
  rays[1].t_far = 9.5f;  // reaches it
  rays[2].origin = Eigen::Vector3f(0, 0, 2);
  rays[2].direction = -Eigen::Vector3f::UnitZ();  // the plane 2 m below
  rays[2].t_near = 2.5f;                          // starts behind it
  std::vector<uint8_t> occluded(rays.size());
  scene.Occluded(rays, occluded);
  EXPECT_EQ(occluded[0], 0);
  EXPECT_EQ(occluded[1], 1);
  EXPECT_EQ(occluded[2], 0);
}

TEST(Raycast, ImageMethodsAndPosesAgree) {
  const RaycastScene scene = MakeScene();
  const ScanGrid grid = UniformGrid(37, 53, -0.3, 0.3, -0.4, 0.2);  // odd sizes: partial tiles
  const cv::Mat directions = DirectionsFromGrid(grid);
  const Eigen::Matrix4d pose = ComposeTransform({0.3, -1, 2}, {0, 0, 5});
  const RayHitImages packet = scene.CastImage(pose, directions, 0.0f, 100.0f, CastMethod::kPacket16);
  const RayHitImages stream = scene.CastImage(pose, directions, 0.0f, 100.0f, CastMethod::kStream);
  const RayHitImages single = scene.CastImage(pose, directions, 0.0f, 100.0f, CastMethod::kSingle);
  const RayHitImages packet8 = scene.CastImage(pose, directions, 0.0f, 100.0f, CastMethod::kPacket8);
  int hits_sphere = 0, misses = 0;
  for (int r = 0; r < directions.rows; ++r) {
    for (int c = 0; c < directions.cols; ++c) {
      for (const RayHitImages* other : {&stream, &single, &packet8}) {
        EXPECT_EQ(packet.geometry_id.at<int32_t>(r, c), other->geometry_id.at<int32_t>(r, c));
        // Primitive ids may differ where a ray passes through a shared edge (a tie); t and the object agree.
        const float a = packet.t_hit.at<float>(r, c), b = other->t_hit.at<float>(r, c);
        if (std::isinf(a)) {
          EXPECT_TRUE(std::isinf(b));
        } else {
          EXPECT_NEAR(a, b, 1e-5f * a);
        }
      }
      hits_sphere += packet.geometry_id.at<int32_t>(r, c) == 8;
      misses += packet.geometry_id.at<int32_t>(r, c) == kInvalidId;
    }
  }
  EXPECT_GT(hits_sphere, 10);
  EXPECT_GT(misses, 10);
  // The pose form equals rotating the directions by hand and casting from the translated origin.
  cv::Mat rotated(directions.size(), CV_32FC3);
  const Eigen::Matrix3f rotation = pose.topLeftCorner<3, 3>().cast<float>();
  for (int r = 0; r < directions.rows; ++r) {
    for (int c = 0; c < directions.cols; ++c) {
      const cv::Vec3f d = directions.at<cv::Vec3f>(r, c);
      const Eigen::Vector3f w = rotation * Eigen::Vector3f(d[0], d[1], d[2]);
      rotated.at<cv::Vec3f>(r, c) = cv::Vec3f(w.x(), w.y(), w.z());
    }
  }
  const RayHitImages by_hand =
      scene.CastImage(Eigen::Vector3f(pose.topRightCorner<3, 1>().cast<float>()), rotated, 0.0f, 100.0f);
  cv::Mat diff;
  cv::absdiff(by_hand.geometry_id, packet.geometry_id, diff);
  EXPECT_EQ(cv::countNonZero(diff), 0);
}

TEST(Raycast, RangesLimitHits) {
  const RaycastScene scene = MakeScene();
  const cv::Mat directions(1, 1, CV_32FC3, cv::Scalar(0, 1, 0));
  const Eigen::Vector3f origin(0, 0, 2);
  EXPECT_EQ(scene.CastImage(origin, directions, 0.0f, 100.0f).geometry_id.at<int32_t>(0, 0), 8);
  EXPECT_EQ(scene.CastImage(origin, directions, 0.0f, 8.5f).geometry_id.at<int32_t>(0, 0), kInvalidId);
  // Starting inside the sphere (t_near past its front) finds the back face.
  EXPECT_NEAR(scene.CastImage(origin, directions, 9.5f, 100).t_hit.at<float>(0, 0), 11.0f, 1e-3f);
}

TEST(Raycast, MisuseThrows) {
  RaycastScene scene;
  scene.AddMesh(MakeBoxMesh({1, 1, 1}), 0);
  EXPECT_THROW(scene.AddMesh(MakeBoxMesh({1, 1, 1}), 0), std::invalid_argument);
  EXPECT_THROW(scene.AddMesh(MakeBoxMesh({1, 1, 1}), -2), std::invalid_argument);
  std::vector<Ray> rays(1);
  std::vector<RayHit> hits(1);
  EXPECT_THROW(scene.Cast(rays, hits), std::logic_error);
  scene.Commit();
  EXPECT_THROW(scene.AddMesh(MakeBoxMesh({1, 1, 1}), 1), std::logic_error);
  RaycastSceneOptions options;
  options.build_quality = "best";
  EXPECT_THROW(RaycastScene scene_with_bad_options(options), OptionsError);
}

}  // namespace
}  // namespace lidarshop
