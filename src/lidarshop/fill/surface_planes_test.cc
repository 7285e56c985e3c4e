#include "lidarshop/fill/surface_planes.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

using fill_internal::SnapToPlanes;

// Noise-free: ground, a wall standing on it 8 m ahead (a concave crease), and a platform 0.5 m high whose
// front face stands 6 m ahead on the right (a concave foot and a convex top edge).
constexpr const char* kCreaseScene = R"({
  "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-30, 30], "elevation_deg": [-25, 15], "columns": 240,
              "rows": 160, "max_range": 60, "seed": 3},
  "objects": [
    {"primitive": "plane", "size": [60, 60], "translate": [0, 20, 0], "label": 0, "color": [120, 120, 110]},
    {"primitive": "box", "size": [30, 0.5, 5], "translate": [-15, 8.25, 2.5], "label": 2, "color": [200, 190, 170]},
    {"primitive": "box", "size": [30, 6, 0.5], "translate": [15, 9, 0.25], "label": 3, "color": [150, 110, 90]}
  ]
})";

struct Crease {
  Scan scan;
  cv::Mat range, known, hole;
};

// The scene's scan with a hole over `box`; `range` holds the scan's ranges, 0 in the hole and where none.
Crease MakeCrease(const cv::Rect& box) {
  Crease c;
  c.scan = SynthesizeScan(ParseScene(kCreaseScene, "crease scene", "."));
  c.hole = cv::Mat::zeros(c.scan.rows, c.scan.cols, CV_8U);
  c.hole(box) = 255;
  c.known = (c.scan.valid != 0) & (c.hole == 0);
  c.range = RangeImage(c.scan);
  c.range.setTo(0, c.known == 0);
  return c;
}

// Ranges of the hole that drifted by `factor`, as a reconstruction far from the border does.
cv::Mat Drifted(const Crease& c, float factor) {
  cv::Mat drifted = RangeImage(c.scan) * factor;
  drifted.setTo(0, c.hole == 0);
  return drifted;
}

// The largest |range − truth| over the hole's cells with a return, metres.
double WorstError(const Crease& c, const cv::Mat& hole_range) {
  const cv::Mat truth = RangeImage(c.scan);
  double worst = 0;
  for (int y = 0; y < c.hole.rows; ++y)
    for (int x = 0; x < c.hole.cols; ++x)
      if (c.hole.at<uint8_t>(y, x) && c.scan.valid.at<uint8_t>(y, x))
        worst = std::max(worst, std::abs(double(hole_range.at<float>(y, x)) - truth.at<float>(y, x)));
  return worst;
}

FillPlaneOptions TrustEveryPlane() {
  FillPlaneOptions options;
  options.agreement_per_m = 1000;  // no patch sources in these tests: let every candidate plane be taken
  return options;
}

// Finds the hole cells of the scan that see `label`.
int CountLabel(const Crease& c, int label) {
  return cv::countNonZero((c.scan.label == label) & (c.hole != 0));
}

TEST(SurfacePlanes, AHiddenConcaveCreaseIsPlacedExactly) {
  // The hole spans the wall's foot: wall above, ground below, the crease inside.
  Crease c = MakeCrease(cv::Rect(40, 70, 40, 40));
  ASSERT_GT(CountLabel(c, 0), 200);
  ASSERT_GT(CountLabel(c, 2), 200);
  for (float factor : {1.06f, 0.95f}) {
    cv::Mat hole_range = Drifted(c, factor);
    const int64_t moved = SnapToPlanes(c.range, c.known, c.scan.direction, c.hole, c.scan.valid, {},
                                       TrustEveryPlane(), 1, &hole_range);
    EXPECT_EQ(moved, cv::countNonZero(c.hole & c.scan.valid)) << factor;
    EXPECT_LT(WorstError(c, hole_range), 0.005) << factor;
  }
}

TEST(SurfacePlanes, AConvexEdgeTakesTheFartherPlane) {
  // The hole spans the platform's front: ground, its face and its top, with both of the face's edges inside.
  Crease c = MakeCrease(cv::Rect(170, 85, 40, 40));
  ASSERT_GT(CountLabel(c, 0), 50);
  ASSERT_GT(CountLabel(c, 3), 200);
  cv::Mat hole_range = Drifted(c, 0.95f);
  ASSERT_GT(WorstError(c, hole_range), 0.3);
  SnapToPlanes(c.range, c.known, c.scan.direction, c.hole, c.scan.valid, {}, TrustEveryPlane(), 1,
               &hole_range);
  // The top is seen at grazing incidence (1 in 6), which turns the least-squares plane's millimetres into
  // centimetres along the ray; a wrong plane at the edges would be off by decimetres.
  EXPECT_LT(WorstError(c, hole_range), 0.03);
}

TEST(SurfacePlanes, WithoutASourceOnlyAPlaneTheReconstructionAgreesWithIsTaken) {
  Crease c = MakeCrease(cv::Rect(40, 70, 40, 40));
  // A 15 % drift far from the border (20 cells, 0.7 m) is more than the default agreement allows a cell
  // with no patch source. In the crease's row, whose known cells left and right lie on different planes (the
  // wall and the ground): where both lie on one, that plane is taken (NothingIsPlacedOffTheWall… below).
  int row = -1;
  for (int y = 71; y < 109 && row < 0; ++y)
    if (c.scan.label.at<int32_t>(y, 39) != c.scan.label.at<int32_t>(y, 80)) row = y;
  ASSERT_GE(row, 0);
  cv::Mat hole_range = Drifted(c, 1.15f);
  const cv::Mat before = hole_range.clone();
  SnapToPlanes(c.range, c.known, c.scan.direction, c.hole, c.scan.valid, {}, FillPlaneOptions{}, 1,
               &hole_range);
  EXPECT_EQ(hole_range.at<float>(row, 60), before.at<float>(row, 60));
  // Disabled: nothing moves.
  FillPlaneOptions off;
  off.enabled = false;
  EXPECT_EQ(SnapToPlanes(c.range, c.known, c.scan.direction, c.hole, c.scan.valid, {}, off, 1, &hole_range),
            0);
}

TEST(SurfacePlanes, NothingIsPlacedOffTheWallItsRowShowsOnBothSides) {
  // A hole 40 cells wide within the wall (no narrow gap), its reconstruction drifted 1.6 m behind the wall or
  // 1.2 m before it: too far for a cell without a source to be put on a plane (agreement_m), and the wall on
  // both sides of every row.
  Crease c = MakeCrease(cv::Rect(40, 30, 40, 24));
  ASSERT_EQ(CountLabel(c, 2), 40 * 24);
  for (float factor : {1.2f, 0.85f}) {
    cv::Mat hole_range = Drifted(c, factor);
    SnapToPlanes(c.range, c.known, c.scan.direction, c.hole, c.scan.valid, {}, FillPlaneOptions{}, 1,
                 &hole_range);
    EXPECT_LT(WorstError(c, hole_range), 0.01) << factor;
  }
}

// Noise-free: two walls meeting in an inner corner 8 m ahead, 13° to the side, on the ground.
constexpr const char* kCornerScene = R"({
  "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [0, 30], "elevation_deg": [-10, 20], "columns": 120,
              "rows": 120, "max_range": 60, "seed": 3},
  "objects": [
    {"primitive": "plane", "size": [60, 60], "translate": [0, 20, 0], "label": 0, "color": [120, 120, 110]},
    {"primitive": "box", "size": [10, 0.3, 5], "translate": [-3, 8, 2.5], "label": 2, "color": [200, 190, 170]},
    {"primitive": "box", "size": [0.3, 10, 5], "translate": [2, 3, 2.5], "label": 3, "color": [170, 190, 200]}
  ]
})";

TEST(SurfacePlanes, ARowFromOneWallToAnotherEndsInTheirCorner) {
  // The hole hides the corner: every row of it starts on one wall and ends on the other. Drifted 10 % towards
  // the scanner, more than agreement_m lets a cell without a source be placed (random seed 94: an inner corner
  // behind a post box filled as a ramp 0.3–0.6 m before it): the rows go onto the nearer of the two planes,
  // which meet concavely.
  Crease c;
  c.scan = SynthesizeScan(ParseScene(kCornerScene, "corner scene", "."));
  c.hole = cv::Mat::zeros(c.scan.rows, c.scan.cols, CV_8U);
  c.hole(cv::Rect(40, 30, 40, 30)) = 255;
  c.known = (c.scan.valid != 0) & (c.hole == 0);
  c.range = RangeImage(c.scan);
  c.range.setTo(0, c.known == 0);
  ASSERT_GT(CountLabel(c, 2), 200);
  ASSERT_GT(CountLabel(c, 3), 200);
  cv::Mat hole_range = Drifted(c, 0.9f);
  SnapToPlanes(c.range, c.known, c.scan.direction, c.hole, c.scan.valid, {}, FillPlaneOptions{}, 1,
               &hole_range);
  EXPECT_LT(WorstError(c, hole_range), 0.01);
}

TEST(SurfacePlanes, OptionsAreChecked) {
  FillPlaneOptions options;
  options.tolerance = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = {};
  options.relief_m = -1;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace lidarshop
