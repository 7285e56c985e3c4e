#include <gtest/gtest.h>

#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(RecolorOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<ResectionOptions>();
  ExpectExactRoundTrip<RecolorOptions>();
  ExpectExactRoundTrip<AlignOptions>();
}

// The one range of --threshold and the editor's threshold_px (they disagreed before AlignOptions).
TEST(RecolorOptionsInfo, AlignThreshold) {
  ExpectRejected<AlignOptions>({{"threshold_px", 0}}, "threshold_px", "out of range (0, 1000]");
  ExpectRejected<AlignOptions>({{"threshold_px", 1000.5}}, "threshold_px", "out of range (0, 1000]");
  ExpectRejected<AlignOptions>({{"model", "affine"}}, "model", "homography|fundamental");
  EXPECT_EQ(FromJson<AlignOptions>({{"threshold_px", 1000}}).threshold_px, 1000);
  AlignOptions bad;
  bad.threshold_px = -1;
  EXPECT_THROW(EstimatePhotoModel({}, bad, "pairs"), OptionsFieldError);
}

// The results' JSON keys in the order `lidarshop align --json` has always written them.
TEST(RecolorOptionsInfo, AlignResultKeys) {
  EXPECT_EQ(InfoOf<LandmarkAlignment>().Keys(),
            (std::vector<std::string>{"model", "scale", "rms_m", "residual_m"}));
  EXPECT_EQ(InfoOf<PhotoPairModel>().Keys(),
            (std::vector<std::string>{"model", "rms_px", "error_px", "inlier"}));
  PhotoPairModel fit;
  fit.model = PhotoModel::kFundamental;
  fit.inlier = {1, 0};
  EXPECT_EQ(ToJson(fit).dump(), R"({"model":"fundamental","rms_px":0.0,"error_px":[],"inlier":[1,0]})");
}

TEST(RecolorOptionsInfo, Errors) {
  ExpectRejected<ResectionOptions>({{"radial_coefficients", 4}}, "radial_coefficients",
                                   "out of range [0, 3]");
  ExpectRejected<RecolorOptions>({{"visibility", "z-buffer"}}, "visibility", "did you mean 'zbuffer'");
  ExpectRejected<RecolorOptions>({{"zbuffer_scale", 0}}, "zbuffer_scale", "out of range (0, 1]");
  ExpectRejected<RecolorOptions>({{"skirt_depth_m", -0.1}}, "skirt_depth_m", "out of range");
  EXPECT_EQ(ToString(PairKind::kPixelPixel), "pixel-pixel");
  ResectionOptions no_photo;
  EXPECT_THROW(no_photo.Check(), OptionsError);  // the photo size is needed to resect
}

}  // namespace lidarshop
