// The synthetic scanner's outputs through files, and the scan mesh.
#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

TEST(ScannerIo, PtxRoundTripOfASyntheticScan) {
  test_scenes::GroundAndBoxOptions options;
  options.rows = 60;
  options.columns = 90;
  options.los_noise_sigma = 0.005;
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene(options));
  const std::string path = (std::filesystem::temp_directory_path() / "scanner_io_test.ptx").string();
  WriteScanFile(path, {scan});
  const ScanFile file = ReadScanFile(path);
  ASSERT_EQ(file.scans.size(), 1u);
  const Scan& read = file.scans[0];
  ASSERT_EQ(read.rows, scan.rows);
  ASSERT_EQ(read.cols, scan.cols);
  EXPECT_LT((read.world_from_scanner - scan.world_from_scanner).norm(), 1e-6);
  int compared = 0;
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      ASSERT_EQ(read.valid.at<uint8_t>(r, c) != 0, scan.valid.at<uint8_t>(r, c) != 0) << r << " " << c;
      if (!scan.valid.at<uint8_t>(r, c)) continue;
      const cv::Vec3f a = scan.point.at<cv::Vec3f>(r, c), b = read.point.at<cv::Vec3f>(r, c);
      EXPECT_LT(cv::norm(a - b), 1e-3) << r << " " << c;
      EXPECT_NEAR(read.intensity.at<float>(r, c), scan.intensity.at<float>(r, c), 1e-3);
      if (read.has_color()) EXPECT_EQ(read.color.at<cv::Vec3b>(r, c), scan.color.at<cv::Vec3b>(r, c));
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000);
  std::filesystem::remove(path);
}

TEST(ScanMesh, JoinsNeighboursAndCutsDepthJumps) {
  // A wall 10 m ahead and, in front of its left half, a panel 5 m ahead: no triangle may join the two.
  ScannerOptions options;
  options.position = Eigen::Vector3d::Zero();
  options.rows = 40;
  options.columns = 60;
  options.azimuth_min_deg = -20;
  options.azimuth_max_deg = 20;
  options.elevation_min_deg = -10;
  options.elevation_max_deg = 10;
  SceneDescription scene = test_scenes::MakeSingleObjectScene(
      TransformMesh(MakePlaneMesh({100, 100}), ComposeTransform({0, 10, 0}, {90, 0, 0})), 0, options);
  SceneObject panel;
  panel.mesh = TransformMesh(MakePlaneMesh({10, 10}), ComposeTransform({-5, 5, 0}, {90, 0, 0}));
  panel.label = 1;
  scene.objects.push_back(panel);
  const Scan scan = test_scenes::ScanScene(scene);
  ASSERT_EQ(scan.CountValid(), scan.num_cells());
  const TriangleMesh mesh = ScanToMesh(scan);
  // Every 2 x 2 block gives 2 triangles except those straddling the step (one column boundary, 39 blocks).
  EXPECT_EQ(mesh.triangles.size(), 2u * 39 * 59 - 2u * 39);
  for (const auto& t : mesh.triangles) {
    const float y0 = mesh.vertices[t[0]].y(), y1 = mesh.vertices[t[1]].y(), y2 = mesh.vertices[t[2]].y();
    EXPECT_LT(std::max({y0, y1, y2}) - std::min({y0, y1, y2}), 0.5f);
    // Faces the scanner: the normal points back towards the origin.
    const Eigen::Vector3f n =
        (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    EXPECT_LT(n.dot(mesh.vertices[t[0]]), 0.0f);
  }
  EXPECT_EQ(mesh.vertex_colors.size(), mesh.vertices.size());
  EXPECT_EQ(mesh.vertex_normals.size(), mesh.vertices.size());
  ScanMeshOptions bad;
  bad.max_range_jump_ratio = 0;
  EXPECT_THROW(ScanToMesh(scan, bad), OptionsError);
  bad = ScanMeshOptions();
  bad.max_edge_m = -1;
  EXPECT_THROW(ScanToMesh(scan, bad), OptionsError);

  // An edge-length limit between the shortest and the longest edge keeps some triangles, none with a longer edge.
  float longest = 0.0f, shortest = 1e9f;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const float length = (mesh.vertices[t[k]] - mesh.vertices[t[(k + 1) % 3]]).norm();
      longest = std::max(longest, length);
      shortest = std::min(shortest, length);
    }
  }
  ScanMeshOptions limited;
  limited.max_edge_m = 0.5 * (shortest + longest);
  const TriangleMesh cut = ScanToMesh(scan, limited);
  EXPECT_GT(cut.triangles.size(), 0u);
  EXPECT_LT(cut.triangles.size(), mesh.triangles.size());
  for (const auto& t : cut.triangles) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE((cut.vertices[t[k]] - cut.vertices[t[(k + 1) % 3]]).norm(), limited.max_edge_m + 1e-6);
    }
  }
}

}  // namespace
}  // namespace lidarshop
