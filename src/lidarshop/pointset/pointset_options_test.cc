#include <gtest/gtest.h>

#include "lidarshop/pointset/clustering.h"
#include "lidarshop/pointset/features.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/hough_planes.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/pointset/region_growing.h"
#include "lidarshop/pointset/registration.h"
#include "lidarshop/pointset/superpixels.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(PointsetOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<RansacPlaneOptions>();
  ExpectExactRoundTrip<IcpOptions>();
  ExpectExactRoundTrip<EuclideanClusterOptions>();
  ExpectExactRoundTrip<KMeansOptions>();
  ExpectExactRoundTrip<GlobalAlignOptions>();
  ExpectExactRoundTrip<SuperpixelOptions>();
  ExpectExactRoundTrip<StatisticalOutlierOptions>();
  ExpectExactRoundTrip<RadiusOutlierOptions>();
  ExpectExactRoundTrip<CropOptions>();
  ExpectExactRoundTrip<NormalOptions>();
  ExpectExactRoundTrip<HoughPlaneOptions>();
  ExpectExactRoundTrip<RegionGrowingOptions>();
}

TEST(PointsetOptionsInfo, Errors) {
  ExpectRejected<RansacPlaneOptions>({{"confidence", 1.0}}, "confidence", "out of range (0, 1)");
  ExpectRejected<RansacPlaneOptions>({{"distance_treshold_m", 0.1}}, "distance_treshold_m",
                                     "did you mean 'distance_threshold_m'");
  ExpectRejected<IcpOptions>({{"min_correspondence_m", 0.5}}, "min_correspondence_m",
                             "above max_correspondence_m");
  ExpectRejected<EuclideanClusterOptions>({{"min_points", 10}, {"max_points", 5}}, "max_points",
                                          "below min_points");
  ExpectRejected<SuperpixelOptions>({{"method", "slick"}}, "method", "did you mean 'slic'");
  ExpectRejected<CropOptions>({{"labels", {1.5}}}, "labels", "whole numbers");
  ExpectRejected<HoughPlaneOptions>({{"angle_step_deg", 45}}, "angle_step_deg", "out of range (0, 30]");
  EXPECT_EQ(ToString(SuperpixelMethod::kGraph), "graph");
}

TEST(PointsetOptionsInfo, GeometryStaysChecked) {
  CropOptions crop;
  crop.polygon = {{0, 0}, {1, 1}};
  EXPECT_THROW(crop.Check(), OptionsError);
}

}  // namespace lidarshop
