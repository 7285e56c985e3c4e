#include "lidarshop/scan/scan_mesh.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// A wavy surface over a 300 x 400 grid with holes and range jumps: the rows are meshed in parallel and joined
// in row order, so one thread and all give the same triangles and vertices, in the same order.
TEST(ScanToMesh, SameMeshOnAnyThreadCount) {
  const int rows = 300, cols = 400;
  Scan scan = MakeScan(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const float range = 5.0f + std::sin(0.05f * c) + ((r / 40 + c / 50) % 3 == 0 ? 3.0f : 0.0f);  // jumps
      const float azimuth = 0.01f * c, elevation = 0.5f - 0.003f * r;
      scan.range.at<float>(r, c) = range;
      scan.point.at<cv::Vec3f>(r, c) =
          cv::Vec3f(range * std::cos(elevation) * std::sin(azimuth),
                    range * std::cos(elevation) * std::cos(azimuth), range * std::sin(elevation));
      scan.valid.at<uint8_t>(r, c) = (r * 7 + c * 13) % 29 != 0;  // scattered holes
    }
  }
  TriangleMesh one;
  {
    const ThreadLimit limit(1);
    one = ScanToMesh(scan);
  }
  const TriangleMesh all = ScanToMesh(scan);
  EXPECT_GT(all.triangles.size(), static_cast<size_t>(rows * cols));  // most quads give two triangles
  EXPECT_LT(all.triangles.size(), static_cast<size_t>(2 * rows * cols * 0.95));  // holes and jumps drop some
  ASSERT_EQ(one.triangles.size(), all.triangles.size());
  ASSERT_EQ(one.vertices.size(), all.vertices.size());
  for (size_t i = 0; i < all.triangles.size(); ++i) ASSERT_EQ(one.triangles[i], all.triangles[i]) << i;
  for (size_t i = 0; i < all.vertices.size(); ++i) ASSERT_EQ(one.vertices[i], all.vertices[i]) << i;
}

}  // namespace
}  // namespace lidarshop
