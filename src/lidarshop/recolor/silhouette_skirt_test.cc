#include "lidarshop/recolor/silhouette_skirt.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/recolor_eval.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/testing/scenes.h"

namespace lidarshop {
namespace {

// A coarse scan (about 1 degree per cell) of MakeRecolorScene: the pillar (label 3) stands in front of the
// wall (label 1).
Scan CoarseScan() { return test_scenes::ScanScene(test_scenes::MakeRecolorScene(false, 60, 90)); }

// The first hit of a ray from the scanner origin (scanner frame) against `mesh`, +inf on a miss.
float FirstHit(const TriangleMesh& mesh, const Eigen::Vector3f& direction) {
  RaycastScene scene;
  scene.AddMesh(mesh, 0);
  scene.Commit();
  Ray ray;
  ray.direction = direction;
  RayHit hit;
  scene.Cast({&ray, 1}, {&hit, 1});
  return hit.t_hit;
}

TEST(SilhouetteSkirt, CapsGrowAnOccluderUpToTheNextRayAtItsOwnRange) {
  const Scan scan = CoarseScan();
  ScanMeshOptions mesh_options;  // scanner frame
  const TriangleMesh mesh = ScanToMesh(scan, mesh_options);
  SilhouetteSkirtOptions skirt_options;
  skirt_options.world_frame = false;
  skirt_options.depth_m = 0;
  const TriangleMesh skirts = SilhouetteSkirts(scan, skirt_options);
  ASSERT_FALSE(skirts.empty());
  int edges = 0;
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c + 1 < scan.cols; ++c) {
      // The pillar's right edge: its last cell, then the wall.
      if (scan.label.at<int32_t>(r, c) != 3 || scan.label.at<int32_t>(r, c + 1) != 1) continue;
      ++edges;
      const cv::Vec3f a = scan.direction.at<cv::Vec3f>(r, c), b = scan.direction.at<cv::Vec3f>(r, c + 1);
      // Three quarters of the way to the wall's ray: the grid mesh has nothing there (both surfaces stop at
      // their last cells), the skirt has the pillar at the pillar's range.
      const Eigen::Vector3f between =
          (0.25f * Eigen::Vector3f(a[0], a[1], a[2]) + 0.75f * Eigen::Vector3f(b[0], b[1], b[2]))
              .normalized();
      EXPECT_FALSE(std::isfinite(FirstHit(mesh, between))) << r << " " << c;
      const float pillar_range = scan.range.at<float>(r, c);
      EXPECT_NEAR(FirstHit(skirts, between), pillar_range, 0.05f * pillar_range) << r << " " << c;
    }
  }
  EXPECT_GT(edges, 5);
}

TEST(SilhouetteSkirt, WallsGoBackAlongTheirRaysByTheirDepth) {
  const Scan scan = CoarseScan();
  SilhouetteSkirtOptions caps;
  caps.world_frame = false;
  SilhouetteSkirtOptions walls = caps;
  walls.depth_m = 0.4;
  const TriangleMesh cap_mesh = SilhouetteSkirts(scan, caps), wall_mesh = SilhouetteSkirts(scan, walls);
  // Each cap (2 triangles, 4 vertices) gets four walls (8 triangles, 4 more vertices).
  ASSERT_EQ(wall_mesh.num_triangles(), 5 * cap_mesh.num_triangles());
  ASSERT_EQ(wall_mesh.num_vertices(), 2 * cap_mesh.num_vertices());
  for (size_t cap = 0; cap < cap_mesh.num_vertices() / 4; ++cap) {
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3f front = wall_mesh.vertices[8 * cap + i],
                            back = wall_mesh.vertices[8 * cap + 4 + i];
      EXPECT_LT((front - cap_mesh.vertices[4 * cap + i]).norm(), 1e-5f);
      EXPECT_LE((back - front).norm(), 0.4f + 1e-4f);
      EXPECT_GE(back.norm(), front.norm() - 1e-4f);  // back along the same ray
      EXPECT_LT((back.normalized() - front.normalized()).norm(), 1e-4f);
    }
  }
  // In the world frame the skirts move with the scanner's pose.
  SilhouetteSkirtOptions world = caps;
  world.world_frame = true;
  const TriangleMesh world_mesh = SilhouetteSkirts(scan, world);
  ASSERT_EQ(world_mesh.num_vertices(), cap_mesh.num_vertices());
  EXPECT_LT((world_mesh.vertices[0] - (cap_mesh.vertices[0] + Eigen::Vector3f(0, 0, 1.5f))).norm(), 1e-4f);
}

// MakeRecolorScene with a post 8 cm square and 2 m tall (label 4) 7 m from the scanner, 5 m before the wall.
SceneDescription SceneWithAThinPost() {
  SceneDescription scene = test_scenes::MakeRecolorScene();
  SceneObject post;
  post.name = "post";
  post.mesh = MakeBoxMesh(Eigen::Vector3d(0.08, 0.08, 2.0));
  post.world_from_object.topRightCorner<3, 1>() = Eigen::Vector3d(0.5, 7, 1.0);
  post.label = 4;
  post.material.color = Rgb8(30, 30, 30);
  scene.objects.push_back(post);
  return scene;
}

TEST(SilhouetteSkirt, AThinOccludersWallsAreNoDeeperThanItsWidth) {
  const Scan scan = test_scenes::ScanScene(SceneWithAThinPost());
  SilhouetteSkirtOptions options;
  options.world_frame = false;  // scanner frame: the world shifted down by the scanner's 1.5 m
  options.depth_m = 0.25;
  options.depth_per_width = 1.0;
  const TriangleMesh limited = SilhouetteSkirts(scan, options);
  options.depth_per_width = 0;
  const TriangleMesh unlimited = SilhouetteSkirts(scan, options);
  // Each cap has 4 front then 4 back vertices; the deepest wall of the caps on the post and on the pillar.
  const auto deepest = [](const TriangleMesh& mesh, const Eigen::Vector2f& centre, float radius) {
    float depth = 0;
    for (size_t cap = 0; cap < mesh.num_vertices() / 8; ++cap) {
      const Eigen::Vector3f front = mesh.vertices[8 * cap], back = mesh.vertices[8 * cap + 4];
      if ((front.head<2>() - centre).norm() < radius) depth = std::max(depth, (back - front).norm());
    }
    return depth;
  };
  const Eigen::Vector2f post(0.5f, 7.0f), pillar(1.6f, 8.0f);
  EXPECT_NEAR(deepest(unlimited, post, 0.15f), 0.25f, 1e-3f);
  // 8 cm and one cell (2.2 cm at 7 m) at most.
  EXPECT_GT(deepest(limited, post, 0.15f), 0.05f);
  EXPECT_LT(deepest(limited, post, 0.15f), 0.12f);
  // The pillar is 0.5 m wide: its walls keep the full depth.
  EXPECT_NEAR(deepest(limited, pillar, 0.4f), 0.25f, 1e-3f);
}

TEST(SilhouetteSkirt, ACameraBesideTheScannerSeesTheWallNextToAThinPost) {
  const SceneDescription scene = SceneWithAThinPost();
  const Scan truth = test_scenes::ScanScene(scene);
  Scan input = Clone(truth);
  input.color.setTo(cv::Scalar(250, 0, 250));
  const PinholeCamera camera = CameraLookingAt({1.5, 0.3, 1.6}, {0, 10, 1.0}, 800, 600, 75);
  const Photo photo = RenderPhoto(scene, camera);
  RecolorOptions full_walls;
  full_walls.skirt_depth_m = 0.25;
  full_walls.skirt_depth_per_width = 0;
  RecolorOptions thin_walls = full_walls;
  thin_walls.skirt_depth_per_width = 1;
  const RecolorResult deep = RecolorScan(input, photo.image, camera, full_walls);
  const RecolorResult limited = RecolorScan(input, photo.image, camera, thin_walls);
  const RecolorScore deep_score = ScoreRecolor(scene, truth, input, deep.scan, camera);
  const RecolorScore score = ScoreRecolor(scene, truth, input, limited.scan, camera);
  SCOPED_TRACE(deep_score.Summary() + "\n" + score.Summary());
  // The post's 25 cm walls hid a strip of the wall the camera sees; the hidden points stay unchanged.
  EXPECT_LT(limited.hidden, deep.hidden);
  EXPECT_GT(score.visible_correct, deep_score.visible_correct);
  EXPECT_EQ(score.hidden_changed, 0);
}

}  // namespace
}  // namespace lidarshop
