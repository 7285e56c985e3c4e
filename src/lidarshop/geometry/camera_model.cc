#include "lidarshop/geometry/camera_model.h"

#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "lidarshop/geometry/camera_json.h"
#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/json_input.h"

namespace lidarshop {

namespace {

constexpr std::pair<CameraModel, const char*> kModelNames[] = {{CameraModel::kPinhole, "pinhole"},
                                                               {CameraModel::kFisheye, "fisheye"},
                                                               {CameraModel::kSpherical, "spherical"},
                                                               {CameraModel::kCylindrical, "cylindrical"}};

// θd(θ) of the equidistant fisheye and its derivative.
double FisheyeDistorted(const double k[4], double theta) {
  const double t2 = theta * theta;
  return theta * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}
double FisheyeSlope(const double k[4], double theta) {
  const double t2 = theta * theta;
  return 1 + t2 * (3 * k[0] + t2 * (5 * k[1] + t2 * (7 * k[2] + t2 * 9 * k[3])));
}

// The azimuth of a column and the column of an azimuth (spherical and cylindrical).
double AzimuthOfColumn(const Camera& camera, double u) {
  return (u - 0.5 * camera.width_px()) * camera.pixel_width_rad;
}
double ColumnOfAzimuth(const Camera& camera, double theta) {
  return 0.5 * camera.width_px() + theta / camera.pixel_width_rad;
}

}  // namespace

const char* CameraModelName(CameraModel model) {
  for (const auto& [value, name] : kModelNames) {
    if (value == model) return name;
  }
  return "unknown";
}

double Camera::PixelAngleRad() const {
  switch (model) {
    case CameraModel::kPinhole:
    case CameraModel::kFisheye:
      return 1.0 / std::max(pinhole.fx_px, pinhole.fy_px);
    case CameraModel::kSpherical:
      return std::max(pixel_width_rad, pixel_height_rad);
    case CameraModel::kCylindrical:
      return std::max(pixel_width_rad, pixel_height_m / radius_m);
  }
  return 0;
}

void Camera::Check(const std::string& what) const {
  if (model == CameraModel::kPinhole) {
    AsPinhole().Check(what);
    return;
  }
  if (width_px() <= 0 || height_px() <= 0)
    ThrowInputError(what, "", "width_px",
                    fmt::format("image size must be > 0, got {} x {}", width_px(), height_px()));
  if (!world_from_camera.allFinite() || !IsRigid(world_from_camera, 1e-6))
    ThrowInputError(what, "", "world_from_camera",
                    "must be a rigid 4x4 transform (rotation and translation)");
  const auto positive = [&](double value, const char* field) {
    if (!std::isfinite(value) || value <= 0)
      ThrowInputError(what, "", field, fmt::format("must be a finite number > 0, got {}", value));
  };
  switch (model) {
    case CameraModel::kPinhole:
      break;
    case CameraModel::kFisheye: {
      positive(pinhole.fx_px, "fx_px");
      positive(pinhole.fy_px, "fy_px");
      for (double value : {pinhole.cx_px, pinhole.cy_px, pinhole.skew_px, fisheye_k[0], fisheye_k[1],
                           fisheye_k[2], fisheye_k[3]}) {
        if (!std::isfinite(value)) ThrowInputError(what, "", "intrinsics", "values must be finite numbers");
      }
      // Unprojection inverts θd(θ): it must grow over [0, π) or two angles would share a pixel.
      for (int i = 0; i <= 1000; ++i) {
        const double theta = M_PI * i / 1001.0;
        if (!(FisheyeSlope(fisheye_k, theta) > 0))
          ThrowInputError(what, "", "distortion",
                          fmt::format("θd(θ) must grow with θ over [0°, 180°); it does not at {:.1f}°",
                                      theta * 180 / M_PI));
      }
      break;
    }
    case CameraModel::kSpherical:
      positive(pixel_width_rad, "pixel_width_rad");
      positive(pixel_height_rad, "pixel_height_rad");
      break;
    case CameraModel::kCylindrical:
      positive(pixel_width_rad, "pixel_width_rad");
      positive(pixel_height_m, "pixel_height_m");
      positive(radius_m, "radius_m");
      if (!std::isfinite(principal_y_px)) ThrowInputError(what, "", "principal_y_px", "must be finite");
      break;
  }
}

PinholeCamera Camera::AsPinhole() const {
  if (model != CameraModel::kPinhole)
    throw std::logic_error(fmt::format("AsPinhole on a {} camera", CameraModelName(model)));
  PinholeCamera camera = pinhole;
  camera.world_from_camera = world_from_camera;
  return camera;
}

Camera CameraFromPinhole(const PinholeCamera& pinhole) {
  Camera camera;
  camera.pinhole = pinhole;
  camera.world_from_camera = pinhole.world_from_camera;
  return camera;
}

Camera SphericalPanorama(int height_px, const Eigen::Matrix4d& world_from_camera) {
  Camera camera;
  camera.model = CameraModel::kSpherical;
  camera.pinhole.width_px = 2 * height_px;
  camera.pinhole.height_px = height_px;
  camera.pixel_width_rad = 2 * M_PI / camera.pinhole.width_px;
  camera.pixel_height_rad = M_PI / height_px;
  camera.world_from_camera = world_from_camera;
  return camera;
}

bool ProjectCameraPoint(const Camera& camera, const Eigen::Vector3d& p, Eigen::Vector2d* pixel_px) {
  // The pinhole first: it needs no rho, and a 10-megapoint station projects every point into every photo.
  if (camera.model == CameraModel::kPinhole) return ProjectCameraPoint(camera.pinhole, p, pixel_px);
  const double rho = std::hypot(p.x(), p.y());
  switch (camera.model) {
    case CameraModel::kPinhole:
      return ProjectCameraPoint(camera.pinhole, p, pixel_px);
    case CameraModel::kFisheye: {
      if (rho == 0 && !(p.z() > 0)) return false;  // behind, on the axis, or the centre itself
      double a = 0, b = 0;
      if (rho > 0) {
        const double theta_d = FisheyeDistorted(camera.fisheye_k, std::atan2(rho, p.z()));
        a = theta_d * p.x() / rho;
        b = theta_d * p.y() / rho;
      }
      const PinholeCamera& k = camera.pinhole;
      *pixel_px = {k.fx_px * a + k.skew_px * b + k.cx_px, k.fy_px * b + k.cy_px};
      return true;
    }
    case CameraModel::kSpherical: {
      if (rho == 0 && p.z() == 0) return false;
      const double theta = std::atan2(p.x(), p.y()), phi = std::atan2(p.z(), rho);
      *pixel_px = {ColumnOfAzimuth(camera, theta), 0.5 * camera.height_px() - phi / camera.pixel_height_rad};
      return true;
    }
    case CameraModel::kCylindrical: {
      if (rho == 0) return false;
      const double theta = std::atan2(p.x(), p.y()), height_m = camera.radius_m * p.z() / rho;
      *pixel_px = {ColumnOfAzimuth(camera, theta), camera.principal_y_px - height_m / camera.pixel_height_m};
      return true;
    }
  }
  return false;
}

bool ProjectWorldPoint(const Camera& camera, const Eigen::Vector3d& point_in_world,
                       Eigen::Vector2d* pixel_px) {
  const Eigen::Matrix3d rotation = camera.world_from_camera.topLeftCorner<3, 3>();
  return ProjectCameraPoint(camera, rotation.transpose() * (point_in_world - camera.center_in_world()),
                            pixel_px);
}

bool UnprojectPixel(const Camera& camera, const Eigen::Vector2d& pixel_px, Eigen::Vector3d* ray) {
  switch (camera.model) {
    case CameraModel::kPinhole:
      *ray = UnprojectPixel(camera.pinhole, pixel_px).normalized();
      return true;
    case CameraModel::kFisheye: {
      const PinholeCamera& k = camera.pinhole;
      const double b = (pixel_px.y() - k.cy_px) / k.fy_px;
      const double a = (pixel_px.x() - k.cx_px - k.skew_px * b) / k.fx_px;
      const double theta_d = std::hypot(a, b);
      if (theta_d == 0) {
        *ray = Eigen::Vector3d::UnitZ();
        return true;
      }
      if (theta_d >= FisheyeDistorted(camera.fisheye_k, M_PI)) return false;  // beyond what the lens sees
      double theta = std::min(theta_d, M_PI);  // Newton on θd(θ) = theta_d; θd grows (Check)
      for (int i = 0; i < 50; ++i) {
        const double step =
            (FisheyeDistorted(camera.fisheye_k, theta) - theta_d) / FisheyeSlope(camera.fisheye_k, theta);
        theta = std::clamp(theta - step, 0.0, M_PI);
        if (std::abs(step) < 1e-15) break;
      }
      const double s = std::sin(theta) / theta_d;
      *ray = {s * a, s * b, std::cos(theta)};
      return true;
    }
    case CameraModel::kSpherical: {
      const double theta = AzimuthOfColumn(camera, pixel_px.x());
      const double phi = (0.5 * camera.height_px() - pixel_px.y()) * camera.pixel_height_rad;
      if (std::abs(phi) > 0.5 * M_PI) return false;
      *ray = {std::sin(theta) * std::cos(phi), std::cos(theta) * std::cos(phi), std::sin(phi)};
      return true;
    }
    case CameraModel::kCylindrical: {
      const double theta = AzimuthOfColumn(camera, pixel_px.x());
      const double height_m = (camera.principal_y_px - pixel_px.y()) * camera.pixel_height_m;
      *ray = Eigen::Vector3d(camera.radius_m * std::sin(theta), camera.radius_m * std::cos(theta), height_m)
                 .normalized();
      return true;
    }
  }
  return false;
}

bool InsideImage(const Camera& camera, const Eigen::Vector2d& pixel_px) {
  return pixel_px.x() >= 0 && pixel_px.y() >= 0 && pixel_px.x() < camera.width_px() &&
         pixel_px.y() < camera.height_px();
}

std::string CameraModelToJson(const Camera& camera) {
  nlohmann::ordered_json json;
  json["model"] = CameraModelName(camera.model);
  if (camera.model == CameraModel::kPinhole) {
    const nlohmann::ordered_json pinhole = nlohmann::ordered_json::parse(CameraToJson(camera.AsPinhole()));
    for (auto it = pinhole.begin(); it != pinhole.end(); ++it) json[it.key()] = it.value();
    return json.dump(2) + "\n";
  }
  json["width_px"] = camera.width_px();
  json["height_px"] = camera.height_px();
  nlohmann::ordered_json units;
  switch (camera.model) {
    case CameraModel::kPinhole:
      break;
    case CameraModel::kFisheye:
      json["fx_px"] = camera.pinhole.fx_px;
      json["fy_px"] = camera.pinhole.fy_px;
      json["cx_px"] = camera.pinhole.cx_px;
      json["cy_px"] = camera.pinhole.cy_px;
      json["skew_px"] = camera.pinhole.skew_px;
      json["distortion"] = {{"k1", camera.fisheye_k[0]},
                            {"k2", camera.fisheye_k[1]},
                            {"k3", camera.fisheye_k[2]},
                            {"k4", camera.fisheye_k[3]}};
      units = {{"intrinsics", "pixels"},
               {"distortion", "theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)"},
               {"camera_frame", "x right, y down, z forward"}};
      break;
    case CameraModel::kSpherical:
      json["pixel_width_rad"] = camera.pixel_width_rad;
      json["pixel_height_rad"] = camera.pixel_height_rad;
      units = {{"camera_frame", "z up, y forward (the centre column), x right; row 0 = up"}};
      break;
    case CameraModel::kCylindrical:
      json["pixel_width_rad"] = camera.pixel_width_rad;
      json["pixel_height_m"] = camera.pixel_height_m;
      json["radius_m"] = camera.radius_m;
      json["principal_y_px"] = camera.principal_y_px;
      units = {{"camera_frame", "z up (the cylinder's axis), y forward (the centre column), x right"}};
      break;
  }
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({camera.world_from_camera(r, 0), camera.world_from_camera(r, 1),
                    camera.world_from_camera(r, 2), camera.world_from_camera(r, 3)});
  }
  json["world_from_camera"] = rows;
  units["world_from_camera"] = "metres";
  units["pixel_origin"] = "(0, 0) = top-left corner of the image, (0.5, 0.5) = centre of pixel (0, 0)";
  json["units"] = units;
  return json.dump(2) + "\n";
}

namespace {

using camera_json::NumberField;

int Size(const nlohmann::json& json, const char* key, const std::string& what) {
  const double value = NumberField(json, key, what, true);
  if (value != std::floor(value) || value < 1 || value > 1e6)
    ThrowInputError(what, "", key, fmt::format("expected a whole number in [1, 1e6], got {}", value));
  return static_cast<int>(value);
}

}  // namespace

Camera ParseCameraModelJson(const std::string& json_text, const std::string& what) {
  const nlohmann::json json = ParseJsonInput(json_text, what);
  if (!json.is_object()) ThrowInputError(what, "", "", "expected a JSON object");
  Camera camera;
  if (const auto it = json.find("model"); it != json.end()) {
    if (!it->is_string()) ThrowInputError(what, "", "model", "expected a string");
    const std::string name = it->get<std::string>();
    bool known = false;
    for (const auto& [value, model_name] : kModelNames) {
      if (name == model_name) camera.model = value, known = true;
    }
    if (!known)
      ThrowInputError(what, "", "model",
                      fmt::format("unknown model '{}' (pinhole, fisheye, spherical or cylindrical)", name));
  }
  if (camera.model == CameraModel::kPinhole) return CameraFromPinhole(ParseCameraJson(json_text, what));
  camera.pinhole.width_px = Size(json, "width_px", what);
  camera.pinhole.height_px = Size(json, "height_px", what);
  camera.world_from_camera = camera_json::WorldFromCamera(json, what);
  switch (camera.model) {
    case CameraModel::kPinhole:
      break;
    case CameraModel::kFisheye:
      camera.pinhole.fx_px = NumberField(json, "fx_px", what, true);
      camera.pinhole.fy_px = NumberField(json, "fy_px", what, true);
      camera.pinhole.cx_px = NumberField(json, "cx_px", what, true);
      camera.pinhole.cy_px = NumberField(json, "cy_px", what, true);
      camera.pinhole.skew_px = NumberField(json, "skew_px", what, false);
      if (const auto d = json.find("distortion"); d != json.end()) {
        if (!d->is_object()) ThrowInputError(what, "", "distortion", "expected an object {k1, k2, k3, k4}");
        for (const auto& [key, value] : d->items()) {
          if (key != "k1" && key != "k2" && key != "k3" && key != "k4")
            ThrowInputError(what, "", "distortion",
                            fmt::format("'{}' is not a fisheye coefficient (k1, k2, k3, k4)", key));
        }
        const char* keys[] = {"k1", "k2", "k3", "k4"};
        for (int i = 0; i < 4; ++i)
          camera.fisheye_k[i] = NumberField(*d, keys[i], what + ": distortion", false);
      }
      break;
    case CameraModel::kSpherical:
      camera.pixel_width_rad = NumberField(json, "pixel_width_rad", what, true);
      camera.pixel_height_rad = NumberField(json, "pixel_height_rad", what, true);
      break;
    case CameraModel::kCylindrical:
      camera.pixel_width_rad = NumberField(json, "pixel_width_rad", what, true);
      camera.pixel_height_m = NumberField(json, "pixel_height_m", what, true);
      camera.radius_m = NumberField(json, "radius_m", what, true);
      camera.principal_y_px = NumberField(json, "principal_y_px", what, true);
      break;
  }
  camera.Check(what);
  return camera;
}

Camera ReadCameraModelJson(const std::string& path) {
  return ParseCameraModelJson(ReadRegularFile(path), path);
}

void WriteCameraModelJson(const std::string& path, const Camera& camera) {
  const std::string text = CameraModelToJson(camera);
  WriteTextAtomically(path, text);
}

}  // namespace lidarshop
