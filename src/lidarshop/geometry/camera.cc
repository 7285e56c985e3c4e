#include "lidarshop/geometry/camera.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "lidarshop/geometry/camera_json.h"
#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"

namespace lidarshop {

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k;
  k << fx_px, skew_px, cx_px, 0, fy_px, cy_px, 0, 0, 1;
  return k;
}

void PinholeCamera::Check(const std::string& what) const {
  if (width_px <= 0 || height_px <= 0)
    ThrowInputError(what, "", "width_px",
                    fmt::format("image size must be > 0, got {} x {}", width_px, height_px));
  const double values[] = {fx_px, fy_px, cx_px, cy_px, skew_px, k1, k2, k3, p1, p2};
  for (double value : values) {
    if (!std::isfinite(value)) ThrowInputError(what, "", "intrinsics", "values must be finite numbers");
  }
  if (fx_px <= 0 || fy_px <= 0)
    ThrowInputError(what, "", "fx_px", fmt::format("focal lengths must be > 0, got {} and {}", fx_px, fy_px));
  if (!world_from_camera.allFinite() || !IsRigid(world_from_camera, 1e-6))
    ThrowInputError(what, "", "world_from_camera",
                    "must be a rigid 4x4 transform (rotation and translation)");
}

PinholeCamera CameraLookingAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, int width_px,
                              int height_px, double horizontal_fov_deg) {
  PinholeCamera camera;
  camera.width_px = width_px;
  camera.height_px = height_px;
  camera.fx_px = camera.fy_px = 0.5 * width_px / std::tan(0.5 * horizontal_fov_deg * M_PI / 180.0);
  camera.cx_px = 0.5 * width_px;
  camera.cy_px = 0.5 * height_px;
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();  // right
  const Eigen::Vector3d y = z.cross(x);                                      // down
  camera.world_from_camera.topLeftCorner<3, 3>() << x, y, z;
  camera.world_from_camera.topRightCorner<3, 1>() = eye;
  return camera;
}

Eigen::Vector2d DistortNormalized(const PinholeCamera& c, const Eigen::Vector2d& n) {
  const double a = n.x(), b = n.y(), r2 = a * a + b * b;
  const double radial = 1 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  return {a * radial + 2 * c.p1 * a * b + c.p2 * (r2 + 2 * a * a),
          b * radial + c.p1 * (r2 + 2 * b * b) + 2 * c.p2 * a * b};
}

Eigen::Vector2d UndistortNormalized(const PinholeCamera& camera, const Eigen::Vector2d& distorted) {
  if (!camera.has_distortion()) return distorted;
  Eigen::Vector2d n = distorted;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector2d step = distorted - DistortNormalized(camera, n);
    n += step;
    if (step.squaredNorm() < 1e-24) break;
  }
  return n;
}

bool ProjectCameraPoint(const PinholeCamera& camera, const Eigen::Vector3d& point_in_camera,
                        Eigen::Vector2d* pixel_px) {
  if (!(point_in_camera.z() > 0)) return false;
  const Eigen::Vector2d d = DistortNormalized(camera, point_in_camera.head<2>() / point_in_camera.z());
  *pixel_px = {camera.fx_px * d.x() + camera.skew_px * d.y() + camera.cx_px,
               camera.fy_px * d.y() + camera.cy_px};
  return true;
}

bool ProjectWorldPoint(const PinholeCamera& camera, const Eigen::Vector3d& point_in_world,
                       Eigen::Vector2d* pixel_px) {
  const Eigen::Matrix3d rotation = camera.world_from_camera.topLeftCorner<3, 3>();
  const Eigen::Vector3d point_in_camera = rotation.transpose() * (point_in_world - camera.center_in_world());
  return ProjectCameraPoint(camera, point_in_camera, pixel_px);
}

Eigen::Vector3d UnprojectPixel(const PinholeCamera& camera, const Eigen::Vector2d& pixel_px) {
  const double b = (pixel_px.y() - camera.cy_px) / camera.fy_px;
  const double a = (pixel_px.x() - camera.cx_px - camera.skew_px * b) / camera.fx_px;
  const Eigen::Vector2d n = UndistortNormalized(camera, {a, b});
  return {n.x(), n.y(), 1.0};
}

bool InsideImage(const PinholeCamera& camera, const Eigen::Vector2d& pixel_px) {
  return pixel_px.x() >= 0 && pixel_px.y() >= 0 && pixel_px.x() < camera.width_px &&
         pixel_px.y() < camera.height_px;
}

std::string CameraToJson(const PinholeCamera& camera) {
  nlohmann::ordered_json json;
  json["width_px"] = camera.width_px;
  json["height_px"] = camera.height_px;
  json["fx_px"] = camera.fx_px;
  json["fy_px"] = camera.fy_px;
  json["cx_px"] = camera.cx_px;
  json["cy_px"] = camera.cy_px;
  json["skew_px"] = camera.skew_px;
  json["distortion"] = {
      {"k1", camera.k1}, {"k2", camera.k2}, {"k3", camera.k3}, {"p1", camera.p1}, {"p2", camera.p2}};
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({camera.world_from_camera(r, 0), camera.world_from_camera(r, 1),
                    camera.world_from_camera(r, 2), camera.world_from_camera(r, 3)});
  }
  json["world_from_camera"] = rows;
  json["units"] = {
      {"intrinsics", "pixels"},
      {"world_from_camera", "metres"},
      {"camera_frame", "x right, y down, z forward"},
      {"pixel_origin", "(0, 0) = top-left corner of the image, (0.5, 0.5) = centre of pixel (0, 0)"}};
  return json.dump(2) + "\n";
}

namespace camera_json {

double NumberField(const nlohmann::json& object, const char* key, const std::string& what, bool required) {
  const auto it = object.find(key);
  if (it == object.end()) {
    if (required) ThrowInputError(what, "", key, "missing");
    return 0.0;
  }
  if (!it->is_number()) ThrowInputError(what, "", key, "expected a number");
  return it->get<double>();
}

Eigen::Matrix4d WorldFromCamera(const nlohmann::json& object, const std::string& what) {
  const auto pose = object.find("world_from_camera");
  if (pose == object.end()) ThrowInputError(what, "", "world_from_camera", "missing");
  if (!pose->is_array() || pose->size() != 4)
    ThrowInputError(what, "", "world_from_camera", "expected 4 rows of 4 numbers");
  Eigen::Matrix4d matrix;
  for (int r = 0; r < 4; ++r) {
    const nlohmann::json& row = (*pose)[r];
    if (!row.is_array() || row.size() != 4)
      ThrowInputError(what, "", "world_from_camera", "expected 4 rows of 4 numbers");
    for (int c = 0; c < 4; ++c) {
      if (!row[c].is_number()) ThrowInputError(what, "", "world_from_camera", "expected numbers");
      matrix(r, c) = row[c].get<double>();
    }
  }
  return matrix;
}

}  // namespace camera_json

namespace {

using camera_json::NumberField;

}  // namespace

PinholeCamera ParseCameraJson(const std::string& json_text, const std::string& what) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& error) {
    ThrowInputError(what, "", "", fmt::format("not valid JSON: {}", error.what()));
  }
  if (!json.is_object()) ThrowInputError(what, "", "", "expected a JSON object");
  // A camera of another model (geometry/camera_model.h) read as a pinhole one would project wrongly.
  if (const auto model = json.find("model"); model != json.end() && *model != "pinhole")
    ThrowInputError(what, "", "model", fmt::format("{}: only pinhole cameras are taken here", model->dump()));
  PinholeCamera camera;
  const auto integer = [&](const char* key) {
    const double value = NumberField(json, key, what, true);
    if (value != std::floor(value) || value < 1 || value > 1e6)
      ThrowInputError(what, "", key, fmt::format("expected a whole number in [1, 1e6], got {}", value));
    return static_cast<int>(value);
  };
  camera.width_px = integer("width_px");
  camera.height_px = integer("height_px");
  camera.fx_px = NumberField(json, "fx_px", what, true);
  camera.fy_px = NumberField(json, "fy_px", what, true);
  camera.cx_px = NumberField(json, "cx_px", what, true);
  camera.cy_px = NumberField(json, "cy_px", what, true);
  camera.skew_px = NumberField(json, "skew_px", what, false);
  if (json.contains("distortion")) {
    const nlohmann::json& d = json["distortion"];
    if (!d.is_object()) ThrowInputError(what, "", "distortion", "expected an object {k1, k2, k3, p1, p2}");
    camera.k1 = NumberField(d, "k1", what + ": distortion", false);
    camera.k2 = NumberField(d, "k2", what + ": distortion", false);
    camera.k3 = NumberField(d, "k3", what + ": distortion", false);
    camera.p1 = NumberField(d, "p1", what + ": distortion", false);
    camera.p2 = NumberField(d, "p2", what + ": distortion", false);
  }
  camera.world_from_camera = camera_json::WorldFromCamera(json, what);
  camera.Check(what);
  return camera;
}

PinholeCamera ReadCameraJson(const std::string& path) { return ParseCameraJson(ReadRegularFile(path), path); }

void WriteCameraJson(const std::string& path, const PinholeCamera& camera) {
  const std::string text = CameraToJson(camera);
  WriteTextAtomically(path, text);
}

}  // namespace lidarshop
