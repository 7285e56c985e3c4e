// The fill continues the surfaces the hole's surroundings show, and only those (issue 30, classes 2 and 5):
// a kerb's thin front face behind a box, the wall behind a person standing next to other people.
#include <algorithm>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/fill/foreground.h"
#include "lidarshop/fill/surface_planes.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/random_scene.h"
#include "lidarshop/scanner/scanner.h"

namespace lidarshop {
namespace {

struct SurroundingsCase {
  Scan scan, truth;
  cv::Mat hole;
};

SurroundingsCase MakeSurroundingsCase(const std::string& json, int margin) {
  const SceneDescription scene = ParseScene(json, "test scene", ".");
  SceneDescription without = scene;
  std::erase_if(without.objects, [](const SceneObject& o) { return o.label == 1; });
  SurroundingsCase c{SynthesizeScan(scene), SynthesizeScan(without), {}};
  c.hole = GrowHole((c.scan.label == 1) & (c.scan.valid != 0), margin);
  return c;
}

// A box on the road before an 18 cm kerb, the pavement and a wall behind: the kerb's face is 10–20 rows high
// in the band around the hole (issue 30, class 2).
constexpr const char* kKerbScene = R"({
  "scanner": {"position": [0, 0, 1.6], "azimuth_deg": [-18, 18], "elevation_deg": [-25, 12], "columns": 300,
              "rows": 300, "max_range": 60, "los_noise_sigma": 0.003, "orthogonal_noise_sigma": 0.0015,
              "seed": 11},
  "objects": [
    {"primitive": "plane", "size": [60, 60], "translate": [0, 20, 0], "label": 0, "texture": "gravel",
     "color": [90, 90, 92]},
    {"primitive": "box", "size": [14, 4, 0.18], "translate": [0, 7.0, 0.09], "label": 2, "color": [160, 158, 150]},
    {"primitive": "wall", "size": [14, 0.3, 3.0], "translate": [0, 9.2, 0], "label": 3, "texture": "brick",
     "color": [150, 80, 60]},
    {"primitive": "box", "size": [0.9, 0.6, 0.9], "translate": [0.1, 4.2, 0.45], "label": 1,
     "color": [40, 60, 170]}
  ]
})";

TEST(FillSurroundings, AKerbFaceBehindABoxIsContinuedNotFloated) {
  const SurroundingsCase c = MakeSurroundingsCase(kKerbScene, 2);
  const FillResult result = FillScan(c.scan, c.hole);
  const FillMetrics m = MeasureFill(result.scan, c.truth, c.hole);
  // Before the face was found (main ff9d1df): 4.4 % floating, RMSE 53.5 mm.
  EXPECT_LT(m.floating_share, 0.005) << "RMSE " << m.range_rmse_mm << " mm";
  EXPECT_LT(m.range_rmse_mm, 25.0);
  EXPECT_GT(result.plane_cells, result.synthesized_cells * 9 / 10);
}

// The kerb's face is found as a plane of its own among the planes of the band around the hole, and RANSAC's
// plane through the road and the pavement at once (2° apart) is not kept.
TEST(FillSurroundings, TheBandHoldsTheKerbFaceAndNoPlaneThroughTwoLevels) {
  const SurroundingsCase c = MakeSurroundingsCase(kKerbScene, 2);
  cv::Mat ids, stats, centroids;
  ASSERT_EQ(cv::connectedComponentsWithStats(c.hole, ids, stats, centroids, 8, CV_32S), 2);
  const cv::Mat range = RangeImage(c.scan);
  const cv::Mat known_valid = (c.scan.valid != 0) & (c.hole == 0);
  const fill_internal::KnownCells known{range, known_valid, c.scan.direction};
  const cv::Rect box(stats.at<int>(1, cv::CC_STAT_LEFT), stats.at<int>(1, cv::CC_STAT_TOP),
                     stats.at<int>(1, cv::CC_STAT_WIDTH), stats.at<int>(1, cv::CC_STAT_HEIGHT));
  double threshold_m = 0;
  const auto planes = fill_internal::BandPlanes(known, ids, 1, box, stats.at<int>(1, cv::CC_STAT_AREA),
                                                FillPlaneOptions{}, 1, &threshold_m);
  // The scanner is 1.6 m above the road; the pavement 0.18 m higher; the kerb's face 5 m ahead (y).
  auto has = [&](const Eigen::Vector3d& normal, double offset_m) {
    return std::any_of(planes.begin(), planes.end(), [&](const fill_internal::SeenPlane& p) {
      return std::abs(p.normal.dot(normal)) > 0.999 && std::abs(p.offset_m - offset_m) < 0.03;
    });
  };
  EXPECT_TRUE(has(Eigen::Vector3d::UnitZ(), 1.6)) << "road";
  EXPECT_TRUE(has(Eigen::Vector3d::UnitZ(), 1.42)) << "pavement";
  EXPECT_TRUE(has(Eigen::Vector3d::UnitY(), 5.0)) << "kerb face";
  for (const auto& p : planes)  // every plane is level, upright or the wall: none tilted between two levels
    EXPECT_TRUE(std::abs(p.normal.z()) > 0.9995 || std::abs(p.normal.z()) < 0.01) << p.normal.transpose();
}

// The evaluation scene kerb_steps: a mailbox on gravel before a 15 cm kerb and two steps up to a terrace.
// RANSAC through three points found the plane through the steps' nosings (6-9° off level: it holds more cells
// within the inlier distance than any one tread), and the fill put the treads' cells on it: 12.8 mm RMSE
// became 22.8 mm when the band's planes were refitted (b7b6b08). The planes come from cells that face their
// way (fill/surface_planes.cc, FacingPlaneCells).
SurroundingsCase KerbStepsCase() {
  SceneDescription scene = LoadScene(LIDARSHOP_SOURCE_DIR "/data/fill_eval/kerb_steps.json");
  SceneDescription without = scene;
  std::erase_if(without.objects, [](const SceneObject& o) { return o.label == 1; });
  SurroundingsCase c{SynthesizeScan(scene), SynthesizeScan(without), {}};
  c.hole = GrowHole((c.scan.label == 1) & (c.scan.valid != 0), 2);
  return c;
}

TEST(FillSurroundings, AFlightOfStepsGivesItsTreadsAndRisersNotThePlaneThroughItsNosings) {
  const SurroundingsCase c = KerbStepsCase();
  cv::Mat ids, stats, centroids;
  ASSERT_EQ(cv::connectedComponentsWithStats(c.hole, ids, stats, centroids, 8, CV_32S), 2);
  const cv::Mat range = RangeImage(c.scan);
  const cv::Mat known_valid = (c.scan.valid != 0) & (c.hole == 0);
  const fill_internal::KnownCells known{range, known_valid, c.scan.direction};
  const cv::Rect box(stats.at<int>(1, cv::CC_STAT_LEFT), stats.at<int>(1, cv::CC_STAT_TOP),
                     stats.at<int>(1, cv::CC_STAT_WIDTH), stats.at<int>(1, cv::CC_STAT_HEIGHT));
  double threshold_m = 0;
  const auto planes = fill_internal::BandPlanes(known, ids, 1, box, stats.at<int>(1, cv::CC_STAT_AREA),
                                                FillPlaneOptions{}, 1, &threshold_m);
  int treads = 0;  // the scanner is 1.5 m above the gravel; kerb, steps and terrace tops at 0.15-0.6 m
  for (const auto& p : planes) {
    EXPECT_TRUE(std::abs(p.normal.z()) > 0.9995 || std::abs(p.normal.z()) < 0.01) << p.normal.transpose();
    if (std::abs(p.normal.z()) > 0.9995)
      for (double top : {0.15, 0.3, 0.45}) treads += std::abs(p.offset_m - (1.5 - top)) < 0.02;
  }
  EXPECT_GE(treads, 1);
}

TEST(FillSurroundings, KerbStepsKeepsItsScore) {
  const SurroundingsCase c = KerbStepsCase();
  double rmse_mm = 0, within = 0;
  for (uint64_t seed = 0; seed < 3; ++seed) {  // fill_eval's three fills
    FillOptions options;
    options.inpaint.seed = seed;
    const FillMetrics m = MeasureFill(FillScan(c.scan, c.hole, options).scan, c.truth, c.hole);
    rmse_mm += m.range_rmse_mm / 3;
    within += m.within_share / 3;
  }
  // Before the refit (ff9d1df): 12.8 mm, 96.5 % within 20 mm; with the refit through the nosings (b7b6b08)
  // 22.8 mm, 94.4 %; issue 30 allows a loss of 0.01 of the share.
  EXPECT_LT(rmse_mm, 14.0);
  EXPECT_GT(within, 0.955);
}

// A random scene (scanner/random_scene.h), its target removed as fill_eval --random-seeds does.
SurroundingsCase RandomCase(uint64_t seed) {
  const SceneDescription scene = RandomScene(seed);
  SceneDescription without = scene;
  std::erase_if(without.objects, [&](const SceneObject& o) { return o.label == scene.target_label; });
  SurroundingsCase c{SynthesizeScan(scene), SynthesizeScan(without), {}};
  c.hole = GrowHole((c.scan.label == scene.target_label) & (c.scan.valid != 0), 2);
  return c;
}

// Random scene 1: a person 9 m before a wall with a recess. The patches are matched on the range's
// gradients, the same on the wall and in its recess, so cells of the recess took the wall's relief from their
// patches and stood 0.23 m before it: 24.5 % of the filled points floated. The cells around the hole, above
// and below or left and right, agree on the recess.
TEST(FillSurroundings, ARecessBehindAPersonKeepsTheDepthTheCellsAroundTheHoleShow) {
  const SurroundingsCase c = RandomCase(1);
  const FillMetrics m = MeasureFill(FillScan(c.scan, c.hole).scan, c.truth, c.hole);
  EXPECT_LT(m.floating_share, 0.05) << "RMSE " << m.range_rmse_mm << " mm";
  EXPECT_LT(m.range_rmse_mm, 60.0);  // before: 111 mm
}

// Random scene 27: a sign on a thin post 28 m before a facade with recessed windows and a door. The post's
// column (8 cells with the margin) took the door's relief from its patches, 0.15 m behind the facade the
// cells beside it show: 25.3 % floating. A narrow gap between two cells on one plane continues that plane.
TEST(FillSurroundings, AThinPostsColumnContinuesTheFacadeBesideIt) {
  const SurroundingsCase c = RandomCase(27);
  const FillMetrics m = MeasureFill(FillScan(c.scan, c.hole).scan, c.truth, c.hole);
  EXPECT_LT(m.floating_share, 0.05) << "RMSE " << m.range_rmse_mm << " mm";
  EXPECT_LT(m.range_rmse_mm, 40.0);  // before: 78 mm
}

// Random scene 30: a person 5 m before a wall, the wall seen left and right of every row of the hole. The
// reconstruction drifted from the person's range on the hole's rim towards the wall and stood before it:
// 18.5 % floating. The wall the rows' ends lie on is taken where nothing beside the cell stands before it.
TEST(FillSurroundings, TheWallARowShowsOnBothSidesOfAPersonIsContinuedBehindHim) {
  const SurroundingsCase c = RandomCase(30);
  const FillMetrics m = MeasureFill(FillScan(c.scan, c.hole).scan, c.truth, c.hole);
  EXPECT_LT(m.floating_share, 0.12) << "RMSE " << m.range_rmse_mm << " mm";
}

// A crate with a person standing against its side, before a wall; the crate is removed. The person's cells
// touch the hole and stand 3 m in front of the wall: they are no source, and the hole shows the wall.
constexpr const char* kTouchingScene = R"({
  "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-12, 12], "elevation_deg": [-14, 10], "columns": 240,
              "rows": 240, "max_range": 60, "los_noise_sigma": 0.003, "seed": 12},
  "objects": [
    {"primitive": "plane", "size": [60, 60], "translate": [0, 20, 0], "label": 0, "texture": "gravel",
     "color": [110, 110, 105]},
    {"primitive": "wall", "size": [20, 0.3, 4.0], "translate": [0, 12, 0], "label": 3, "color": [200, 200, 190]},
    {"primitive": "box", "size": [0.5, 0.3, 0.9], "translate": [0.95, 9, 0.45], "label": 2, "color": [30, 30, 120]},
    {"primitive": "box", "size": [0.5, 0.3, 0.7], "translate": [0.95, 9, 1.25], "label": 2, "color": [200, 40, 40]},
    {"primitive": "sphere", "radius": 0.12, "translate": [0.95, 9, 1.75], "label": 2, "color": [220, 180, 150]},
    {"primitive": "box", "size": [1.4, 0.6, 1.0], "translate": [0, 9, 0.5], "label": 1, "color": [90, 140, 60]}
  ]
})";

TEST(FillSurroundings, ATouchingPersonIsNeitherCopiedNorTheHolesBorder) {
  const SurroundingsCase c = MakeSurroundingsCase(kTouchingScene, 2);
  const FillResult result = FillScan(c.scan, c.hole);
  FillOptions old;
  old.background_only = false;
  const FillResult before = FillScan(c.scan, c.hole, old);
  const FillMetrics m = MeasureFill(result.scan, c.truth, c.hole);
  const FillMetrics b = MeasureFill(before.scan, c.truth, c.hole);
  int feet_row = 0;  // the lowest row of the person
  for (int y = 0; y < c.scan.rows; ++y)
    for (int x = 0; x < c.scan.cols; ++x)
      if (c.scan.label.at<int32_t>(y, x) == 2 && c.scan.valid.at<uint8_t>(y, x))
        feet_row = std::max(feet_row, y);
  EXPECT_GT(result.front_cells, 100);
  EXPECT_EQ(before.front_cells, 0);
  EXPECT_LT(m.floating_share, 0.01) << "without the rule " << b.floating_share;
  EXPECT_LE(m.floating_share, b.floating_share);
  // Hole cells copied from the person (label 2): only from the rows of its feet, where its legs and the ground
  // meet at one range (no depth jump tells them apart); before, from its whole body.
  auto from_person = [&](const FillResult& fill, int* above_feet) {
    int count = 0;
    for (int y = 0; y < c.hole.rows; ++y) {
      for (int x = 0; x < c.hole.cols; ++x) {
        const cv::Vec2i s = fill.source_cell.at<cv::Vec2i>(y, x);
        if (!c.hole.at<uint8_t>(y, x) || s[0] < 0 || c.scan.label.at<int32_t>(s[0], s[1]) != 2) continue;
        ++count;
        *above_feet += s[0] < feet_row - 6;
      }
    }
    return count;
  };
  int above_now = 0, above_before = 0;
  const int now = from_person(result, &above_now), then = from_person(before, &above_before);
  EXPECT_EQ(above_now, 0) << now << " cells from the person";
  EXPECT_GT(above_before, 100) << then << " cells from the person without the rule";
  // Everything outside the hole is the input's, the person's cells included.
  for (int y = 0; y < c.hole.rows; ++y) {
    for (int x = 0; x < c.hole.cols; ++x) {
      if (c.hole.at<uint8_t>(y, x)) continue;
      ASSERT_EQ(result.scan.valid.at<uint8_t>(y, x), c.scan.valid.at<uint8_t>(y, x));
      ASSERT_EQ(result.scan.range.at<float>(y, x), c.scan.range.at<float>(y, x));
    }
  }
}

// FrontCells on one row: a run before farther cells on both sides is in front, the wall between two parts of
// the hole is not, a run reaching the border is not.
TEST(FillSurroundings, FrontCellsAlongARow) {
  //                      0    1    2    3    4    5    6    7    8    9    10   11
  const float r[12] = {10, 10, 6, 6, 10, 0, 0, 10, 10, 0, 10, 4};
  cv::Mat range(1, 12, CV_32F), known(1, 12, CV_8U), hole(1, 12, CV_8U, cv::Scalar(0));
  for (int x = 0; x < 12; ++x) {
    range.at<float>(0, x) = r[x];
    known.at<uint8_t>(0, x) = r[x] > 0 ? 255 : 0;
  }
  hole.at<uint8_t>(0, 5) = hole.at<uint8_t>(0, 6) = 255;  // cells 5, 6: the hole; 9: no return
  const cv::Mat front = fill_internal::FrontCells(range, known, hole, 0.03, 8);
  EXPECT_EQ(front.at<uint8_t>(0, 2), 255);  // 6 m between 10 m walls
  EXPECT_EQ(front.at<uint8_t>(0, 3), 255);
  EXPECT_EQ(front.at<uint8_t>(0, 4), 0);   // wall: the wall continues beyond the hole
  EXPECT_EQ(front.at<uint8_t>(0, 7), 0);   // wall: the same wall beyond the hole
  EXPECT_EQ(front.at<uint8_t>(0, 10), 0);  // nearer cell on its right
  EXPECT_EQ(front.at<uint8_t>(0, 11), 0);  // reaches the border
  EXPECT_EQ(front.at<uint8_t>(0, 0), 0);
  // A dropout of a few cells is not open space behind a run: the surface beyond it decides.
  cv::Mat row(1, 30, CV_32F, cv::Scalar(10)), row_known(1, 30, CV_8U, cv::Scalar(255));
  const cv::Mat no_hole(1, 30, CV_8U, cv::Scalar(0));
  for (int x = 10; x < 13; ++x) row_known.at<uint8_t>(0, x) = 0, row.at<float>(0, x) = 0;  // a dropout
  for (int x = 20; x < 29; ++x) row_known.at<uint8_t>(0, x) = 0, row.at<float>(0, x) = 0;  // open space
  // Cells 13..19 at 10 m: 3 cells without a return and the same surface on their left, 9 on their right.
  EXPECT_EQ(fill_internal::FrontCells(row, row_known, no_hole, 0.03, 12).at<uint8_t>(0, 15), 0);
  // With a wall 10 m farther beyond the dropout, they stand in front (open space on the right).
  for (int x = 0; x < 10; ++x) row.at<float>(0, x) = 20;
  EXPECT_EQ(fill_internal::FrontCells(row, row_known, no_hole, 0.03, 12).at<uint8_t>(0, 15), 255);
}

}  // namespace
}  // namespace lidarshop
