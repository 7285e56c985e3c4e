// Cameras of photos stored in E57 files (io/e57.h: images2D). A pinhole entry stores its pose and intrinsics
// in metres (focal length, pixel size) and pixels (principal point); lidarshop's camera (geometry/camera.h)
// is in pixels. The E57 camera frame is taken as lidarshop's: x along increasing columns, y along increasing
// rows, z the viewing direction; the principal point is used as stored.
#pragma once

#include <string>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/io/e57.h"

namespace lidarshop {

// True and `camera` filled when `image` is a pinhole entry with a decoded photo, a focal length and pixel
// sizes; else false and `why` says what is missing.
bool CameraFromE57Image(const E57Image& image, PinholeCamera* camera, std::string* why);

}  // namespace lidarshop
