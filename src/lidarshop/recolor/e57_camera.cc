#include "lidarshop/recolor/e57_camera.h"

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"

namespace lidarshop {

bool CameraFromE57Image(const E57Image& image, PinholeCamera* camera, std::string* why) {
  if (image.projection != "pinhole") {
    *why = fmt::format("image '{}' is a {} image, not a pinhole one: give --camera or --correspondences",
                       image.name, image.projection);
    return false;
  }
  if (image.image.empty()) {
    *why = fmt::format("image '{}' does not decode: {}", image.name, image.decode_error);
    return false;
  }
  if (!(image.focal_length_m > 0 && image.pixel_width_m > 0 && image.pixel_height_m > 0)) {
    *why = fmt::format("image '{}' stores no focal length or pixel size", image.name);
    return false;
  }
  if (!IsRigid(image.world_from_camera, 1e-6)) {
    *why = fmt::format("image '{}' has a pose that is not rigid", image.name);
    return false;
  }
  camera->width_px = image.image.cols;
  camera->height_px = image.image.rows;
  camera->fx_px = image.focal_length_m / image.pixel_width_m;
  camera->fy_px = image.focal_length_m / image.pixel_height_m;
  camera->cx_px = image.principal_x_px;
  camera->cy_px = image.principal_y_px;
  camera->skew_px = 0;
  camera->k1 = camera->k2 = camera->k3 = camera->p1 = camera->p2 = 0;
  camera->world_from_camera = image.world_from_camera;
  return true;
}

std::vector<E57ImageSummary> SummarizeE57Images(const std::vector<E57Image>& images) {
  std::vector<E57ImageSummary> summaries;
  for (size_t i = 0; i < images.size(); ++i) {
    E57ImageSummary summary = SummarizeE57Image(images[i], static_cast<int>(i));
    PinholeCamera camera;
    std::string why;
    summary.recolor_ready = CameraFromE57Image(images[i], &camera, &why);
    summaries.push_back(std::move(summary));
  }
  return summaries;
}

}  // namespace lidarshop
