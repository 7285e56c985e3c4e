#include <gtest/gtest.h>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/texture.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(ScannerOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<ScannerOptions>();
  ExpectExactRoundTrip<PhotoOptions>();
  ExpectExactRoundTrip<ScanMeshOptions>();
  ExpectExactRoundTrip<CarMeshOptions>();
  ExpectExactRoundTrip<FacadeMeshOptions>();
  ExpectExactRoundTrip<RaycastSceneOptions>();
}

TEST(ScannerOptionsInfo, Errors) {
  ExpectRejected<ScannerOptions>({{"elevation_min_deg", -91}}, "elevation_min_deg", "out of range [-90, 90]");
  ExpectRejected<ScannerOptions>({{"azimuth_min_deg", 10}, {"azimuth_max_deg", 5}}, "azimuth_max_deg",
                                 "above azimuth_min_deg");
  ExpectRejected<ScannerOptions>({{"cast_method", "packet4"}}, "cast_method",
                                 "packet16|packet8|stream|single");
  ExpectRejected<CarMeshOptions>({{"style", "sedans"}}, "style", "did you mean 'sedan'");
  ExpectRejected<RaycastSceneOptions>({{"build_quality", "best"}}, "build_quality",
                                      "not low, medium or high");
}

TEST(ScannerOptionsInfo, SceneFileWordsStayInputErrors) {
  EXPECT_EQ(ParseCarStyle("suv", "scene.json"), CarStyle::kVan);
  EXPECT_EQ(ToString(TextureKind::kGravel), "gravel");
  try {
    ParseTextureKind("marble", "scene.json");
    ADD_FAILURE();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("scene.json"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("texture"), std::string::npos);
  }
}

}  // namespace lidarshop
