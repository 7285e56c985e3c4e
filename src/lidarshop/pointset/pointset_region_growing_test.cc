// Region growing over the grid of a synthetic scan: the ground and the faces of a box come out as separate
// smooth regions (true normals), and the front never crosses the depth jump between the box and the ground.
#include <set>

#include <gtest/gtest.h>

#include "lidarshop/pointset/region_growing.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

TEST(RegionGrowingTest, SmoothRegionsFollowTheObjects) {
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  ASSERT_FALSE(scan.label.empty());
  int regions = 0;
  const cv::Mat labels =
      SegmentByRegionGrowing(scan, {.min_region_cells = 20}, NormalAngleCondition(scan, 10.0), &regions);
  EXPECT_GE(regions, 2);  // the ground, the box's front face, its top
  EXPECT_LE(regions, 4);
  // Every region lies on one object (ground label 0 or box label 1).
  std::vector<std::set<int32_t>> objects(regions);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const int32_t region = labels.at<int32_t>(row, col);
      if (region >= 0) objects[region].insert(scan.label.at<int32_t>(row, col));
    }
  }
  for (const auto& set : objects) EXPECT_EQ(set.size(), 1u);
  // The region of the bottom-centre cell (ground) is the whole visible ground.
  const cv::Point ground_seed(scan.cols / 2, scan.rows - 1);
  const cv::Mat ground = GrowRegion(scan, ground_seed, {}, NormalAngleCondition(scan, 10.0));
  const int ground_cells = cv::countNonZero(scan.label == 0 & scan.valid);
  EXPECT_NEAR(cv::countNonZero(ground), ground_cells, ground_cells * 0.01);
  EXPECT_EQ(cv::countNonZero(ground & (scan.label == 1)), 0);
}

TEST(RegionGrowingTest, BadSeedAndMissingNormals) {
  Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  EXPECT_THROW(GrowRegion(scan, {-1, 0}, {}, [](cv::Point, cv::Point) { return true; }), InputError);
  scan.normal = cv::Mat();
  EXPECT_THROW(NormalAngleCondition(scan, 10.0), InputError);
  EXPECT_THROW(RegionGrowingOptions{.max_range_jump_ratio = 0.0}.Check(), OptionsError);
}

}  // namespace
}  // namespace lidarshop
