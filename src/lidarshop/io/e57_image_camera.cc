#include "lidarshop/io/e57_image_camera.h"

#include <cmath>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {

// A nominal pixel size for pinhole entries written from pixel intrinsics: E57 wants metres, lidarshop's
// cameras are in pixels; only the ratio focalLength / pixelWidth matters.
constexpr double kNominalPixelM = 1e-5;

}  // namespace

std::string E57ImageModel(const E57Image& image) {
  if (image.projection == "pinhole" || image.projection == "spherical" || image.projection == "cylindrical")
    return image.projection;
  return "";
}

bool CameraModelOfE57Image(const E57Image& image, Camera* camera, std::string* why) {
  const std::string model = E57ImageModel(image);
  if (model.empty()) {
    *why = fmt::format("image '{}' is a {} image: it has no camera model", image.name, image.projection);
    return false;
  }
  int width = image.width_px, height = image.height_px;
  if (!image.image.empty()) {
    if ((width && width != image.image.cols) || (height && height != image.image.rows)) {
      *why = fmt::format("image '{}' states {} x {} pixels but its photo is {} x {}", image.name, width,
                         height, image.image.cols, image.image.rows);
      return false;
    }
    width = image.image.cols, height = image.image.rows;
  }
  if (width <= 0 || height <= 0) {
    *why = fmt::format("image '{}' has no size", image.name);
    return false;
  }
  if (!image.world_from_camera.allFinite() || !IsRigid(image.world_from_camera, 1e-6)) {
    *why = fmt::format("image '{}' has a pose that is not rigid", image.name);
    return false;
  }
  Camera result;
  result.pinhole.width_px = width;
  result.pinhole.height_px = height;
  result.world_from_camera = image.world_from_camera;
  const auto positive = [&](double value) { return std::isfinite(value) && value > 0; };
  if (model == "pinhole") {
    if (!positive(image.focal_length_m) || !positive(image.pixel_width_m) ||
        !positive(image.pixel_height_m)) {
      *why = fmt::format("image '{}' stores no focal length or pixel size", image.name);
      return false;
    }
    result.model = CameraModel::kPinhole;
    result.pinhole.fx_px = image.focal_length_m / image.pixel_width_m;
    result.pinhole.fy_px = image.focal_length_m / image.pixel_height_m;
    result.pinhole.cx_px = image.principal_x_px;
    result.pinhole.cy_px = image.principal_y_px;
  } else if (model == "spherical") {
    if (!positive(image.pixel_width_rad) || !positive(image.pixel_height_rad)) {
      *why = fmt::format("image '{}' stores no pixel size (radians)", image.name);
      return false;
    }
    result.model = CameraModel::kSpherical;
    result.pixel_width_rad = image.pixel_width_rad;
    result.pixel_height_rad = image.pixel_height_rad;
  } else {
    if (!positive(image.pixel_width_rad) || !positive(image.pixel_height_m) || !positive(image.radius_m)) {
      *why = fmt::format("image '{}' stores no pixel size or radius", image.name);
      return false;
    }
    result.model = CameraModel::kCylindrical;
    result.pixel_width_rad = image.pixel_width_rad;
    result.pixel_height_m = image.pixel_height_m;
    result.radius_m = image.radius_m;
    result.principal_y_px = image.principal_y_px;
  }
  try {
    result.Check(image.name);
  } catch (const InputError& error) {
    *why = error.what();
    return false;
  }
  *camera = result;
  return true;
}

E57Image E57ImageOfCamera(const Camera& camera, const cv::Mat& rgb, const std::string& name,
                          const std::string& what) {
  camera.Check(what);
  if (rgb.type() != CV_8UC3 || rgb.cols != camera.width_px() || rgb.rows != camera.height_px())
    ThrowInputError(what, "", "image",
                    fmt::format("expected an 8-bit RGB photo of {} x {} pixels, got {} x {}",
                                camera.width_px(), camera.height_px(), rgb.cols, rgb.rows));
  E57Image image;
  image.name = name;
  image.image = rgb;
  image.width_px = rgb.cols;
  image.height_px = rgb.rows;
  image.world_from_camera = camera.world_from_camera;
  switch (camera.model) {
    case CameraModel::kPinhole:
      if (camera.pinhole.has_distortion() || camera.pinhole.skew_px != 0)
        ThrowInputError(
            what, "", "distortion",
            "E57's pinholeRepresentation holds no distortion nor skew: undistort the photo first");
      image.projection = "pinhole";
      image.pixel_width_m = kNominalPixelM;
      image.focal_length_m = camera.pinhole.fx_px * kNominalPixelM;
      image.pixel_height_m = image.focal_length_m / camera.pinhole.fy_px;
      image.principal_x_px = camera.pinhole.cx_px;
      image.principal_y_px = camera.pinhole.cy_px;
      break;
    case CameraModel::kFisheye:
      ThrowInputError(what, "", "model",
                      "E57 has no fisheye representation (pinhole, spherical, cylindrical)");
    case CameraModel::kSpherical:
      image.projection = "spherical";
      image.pixel_width_rad = camera.pixel_width_rad;
      image.pixel_height_rad = camera.pixel_height_rad;
      break;
    case CameraModel::kCylindrical:
      image.projection = "cylindrical";
      image.pixel_width_rad = camera.pixel_width_rad;
      image.pixel_height_m = camera.pixel_height_m;
      image.radius_m = camera.radius_m;
      image.principal_y_px = camera.principal_y_px;
      break;
  }
  return image;
}

}  // namespace lidarshop
