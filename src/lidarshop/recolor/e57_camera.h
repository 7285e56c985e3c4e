// Cameras of photos stored in E57 files (io/e57.h: images2D). A pinhole entry stores its pose and intrinsics
// in metres (focal length, pixel size) and pixels (principal point); lidarshop's camera (geometry/camera.h)
// is in pixels. The E57 camera frame is taken as lidarshop's: x along increasing columns, y along increasing
// rows, z the viewing direction; the principal point is used as stored.
#pragma once

#include <string>
#include <vector>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/scan_summary.h"

namespace lidarshop {

// True and `camera` filled when `image` is a pinhole entry with a decoded photo, a focal length and pixel
// sizes; else false and `why` says what is missing.
bool CameraFromE57Image(const E57Image& image, PinholeCamera* camera, std::string* why);

// The photos of an E57 file as `lidarshop photos` lists them (io/scan_summary.h: SummarizeE57Image), each
// with whether recolouring can use it as it is (CameraFromE57Image).
std::vector<E57ImageSummary> SummarizeE57Images(const std::vector<E57Image>& images);

}  // namespace lidarshop
