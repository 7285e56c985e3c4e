#include "lidarshop/render/render_view.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/json_input.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

// Grey of points when the scan has neither colour nor intensity.
constexpr uint8_t kPlainGrey = 200;

void PointViewOptions::Check() const {
  Validate(*this);
  CheckOption(
      eye_in_world.allFinite() && target_in_world.allFinite() && (target_in_world - eye_in_world).norm() > 0,
      "PointViewOptions: the eye and the target must be finite and distinct");
  const Eigen::Vector3d forward = target_in_world - eye_in_world;
  CheckOption(
      up_in_world.allFinite() &&
          (up_in_world.isZero(0) || forward.normalized().cross(up_in_world.normalized()).norm() > 1e-6),
      "PointViewOptions: up must be finite and not parallel to the line of sight (zero = the scan's up)");
}

Eigen::Vector3d ScanUpInWorld(const Scan& scan) {
  return scan.world_from_scanner.topLeftCorner<3, 3>().col(2).normalized();
}

cv::Mat RenderPointView(const Scan& scan, const PointViewOptions& options) {
  options.Check();
  const Eigen::Vector3d forward = (options.target_in_world - options.eye_in_world).normalized();
  const Eigen::Vector3d up_wanted = options.up_in_world.isZero(0) ? ScanUpInWorld(scan) : options.up_in_world;
  Eigen::Vector3d right = forward.cross(up_wanted);
  if (right.norm() < 1e-6) {  // looking straight along the scan's up: any right will do
    right = forward.cross(forward.unitOrthogonal());
  }
  right.normalize();
  const Eigen::Vector3d up = right.cross(forward);
  const double focal = 0.5 * options.width_px / std::tan(0.5 * options.field_of_view_deg * M_PI / 180.0);
  cv::Mat image(options.height_px, options.width_px, CV_8UC3, cv::Scalar::all(0));
  cv::Mat depth(options.height_px, options.width_px, CV_32F,
                cv::Scalar(std::numeric_limits<float>::infinity()));
  const int half = options.point_size_px / 2;
  for (int y = 0; y < scan.rows; ++y) {
    for (int x = 0; x < scan.cols; ++x) {
      if (!scan.valid.at<uint8_t>(y, x)) continue;
      const cv::Vec3f p = scan.point.at<cv::Vec3f>(y, x);
      const Eigen::Vector3d point_in_world =
          (scan.world_from_scanner * Eigen::Vector4d(p[0], p[1], p[2], 1.0)).head<3>();
      const Eigen::Vector3d d = point_in_world - options.eye_in_world;
      const double z = d.dot(forward);
      if (z < 0.05) continue;
      const int u = static_cast<int>(std::floor(0.5 * options.width_px + focal * d.dot(right) / z));
      const int v = static_cast<int>(std::floor(0.5 * options.height_px - focal * d.dot(up) / z));
      cv::Vec3b color;
      if (scan.has_color()) {
        color = scan.color.at<cv::Vec3b>(y, x);
      } else if (scan.has_intensity()) {
        const auto grey = cv::saturate_cast<uint8_t>(255.0f * scan.intensity.at<float>(y, x));
        color = cv::Vec3b(grey, grey, grey);
      } else {
        color = cv::Vec3b(kPlainGrey, kPlainGrey, kPlainGrey);
      }
      if (options.synthesized_tint > 0 && !scan.synthesized.empty() && scan.synthesized.at<uint8_t>(y, x)) {
        const double t = options.synthesized_tint;
        color = cv::Vec3b(cv::saturate_cast<uint8_t>((1 - t) * color[0] + t * 255),
                          cv::saturate_cast<uint8_t>((1 - t) * color[1]),
                          cv::saturate_cast<uint8_t>((1 - t) * color[2] + t * 255));
      }
      for (int dv = -half; dv < options.point_size_px - half; ++dv) {
        for (int du = -half; du < options.point_size_px - half; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || uu >= options.width_px || vv < 0 || vv >= options.height_px) continue;
          float& best = depth.at<float>(vv, uu);
          if (z < best) {
            best = static_cast<float>(z);
            image.at<cv::Vec3b>(vv, uu) = color;
          }
        }
      }
    }
  }
  return image;
}

namespace {

// The median range of the returns among `cells` (CV_8U), or NaN when none returned.
double MedianRange(const Scan& scan, const cv::Mat& cells) {
  std::vector<float> ranges;
  for (int y = 0; y < scan.rows; ++y) {
    for (int x = 0; x < scan.cols; ++x) {
      if (cells.at<uint8_t>(y, x) && scan.valid.at<uint8_t>(y, x))
        ranges.push_back(scan.range.at<float>(y, x));
    }
  }
  if (ranges.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  return ranges[ranges.size() / 2];
}

}  // namespace

PointViewOptions SideView(const Scan& scan, const cv::Mat& region, double angle_deg,
                          const Eigen::Vector3d& up_in_world) {
  CheckScan(scan);
  LIDARSHOP_CHECK(region.size() == cv::Size(scan.cols, scan.rows) && region.type() == CV_8U);
  // The centre: along the mean direction of the returns in a ring around the region, at their median range.
  // Neither changes when the cells inside the region are edited; the region's own cell directions would (a
  // grid fitted to the returns, as readers of real scans fit it, moves with them).
  const cv::Mat inside = region != 0;
  cv::Mat ring;
  double distance_m = std::numeric_limits<double>::quiet_NaN();
  if (cv::countNonZero(inside) < scan.num_cells()) {
    for (const int width : {3, 10, 30, 100}) {
      cv::Mat grown;
      cv::dilate(inside, grown, cv::Mat(), cv::Point(-1, -1), width);
      ring = grown & ~inside;
      distance_m = MedianRange(scan, ring);
      if (!std::isnan(distance_m)) break;
    }
  }
  const Eigen::Vector3d scanner = scan.world_from_scanner.topRightCorner<3, 1>();
  Eigen::Vector3d centre;
  if (!std::isnan(distance_m)) {
    Eigen::Vector3d direction_sum = Eigen::Vector3d::Zero();
    for (int y = 0; y < scan.rows; ++y) {
      for (int x = 0; x < scan.cols; ++x) {
        const float range = scan.range.at<float>(y, x);
        if (!ring.at<uint8_t>(y, x) || !scan.valid.at<uint8_t>(y, x) || !(range > 0)) continue;
        const cv::Vec3f p = scan.point.at<cv::Vec3f>(y, x);
        direction_sum += Eigen::Vector3d(p[0], p[1], p[2]) / range;
      }
    }
    // A ring all around the scanner (a region that is a band of the panorama) has no mean: look forward.
    const Eigen::Vector3d direction_in_scanner =
        direction_sum.norm() > 1e-9 ? Eigen::Vector3d(direction_sum.normalized()) : Eigen::Vector3d::UnitY();
    centre = scanner + scan.world_from_scanner.topLeftCorner<3, 3>() * direction_in_scanner * distance_m;
  } else {
    // No ring (the whole scan, or a region in the sky): the median of the region's returns on each world axis
    // (else of all returns), which a far wall or a few distant points do not pull away as they pull a mean.
    std::vector<double> coordinates[3];
    for (const cv::Mat& cells : {inside, cv::Mat(scan.valid != 0)}) {
      for (int y = 0; y < scan.rows; ++y) {
        for (int x = 0; x < scan.cols; ++x) {
          if (!cells.at<uint8_t>(y, x) || !scan.valid.at<uint8_t>(y, x)) continue;
          const Eigen::Vector3d p = WorldPointOfCell(scan, y, x);
          for (int k = 0; k < 3; ++k) coordinates[k].push_back(p[k]);
        }
      }
      if (!coordinates[0].empty()) break;
    }
    centre = scanner + scan.world_from_scanner.topLeftCorner<3, 3>().col(1);  // nothing returned: 1 m ahead
    for (int k = 0; k < 3 && !coordinates[0].empty(); ++k) {
      std::vector<double>& values = coordinates[k];
      std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
      centre[k] = values[values.size() / 2];
    }
  }
  const Eigen::Vector3d up =
      up_in_world.isZero(0) ? ScanUpInWorld(scan) : Eigen::Vector3d(up_in_world.normalized());
  const Eigen::Vector3d turned = Eigen::AngleAxisd(angle_deg * M_PI / 180.0, up) * (scanner - centre);
  PointViewOptions view;
  view.eye_in_world = centre + turned;
  view.target_in_world = centre;
  view.up_in_world = up;
  return view;
}

namespace {

std::vector<double> XyzList(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

PointViewCamera CameraOf(const PointViewOptions& view, const Scan& scan) {
  PointViewCamera camera;
  camera.eye = XyzList(view.eye_in_world);
  camera.target = XyzList(view.target_in_world);
  camera.up = XyzList(view.up_in_world.isZero(0) ? ScanUpInWorld(scan) : view.up_in_world);
  camera.fov_deg = view.field_of_view_deg;
  camera.width = view.width_px;
  camera.height = view.height_px;
  return camera;
}

void ParseCameraJson(const std::string& text, const std::string& what, PointViewOptions* view) {
  const nlohmann::json doc = ParseJsonInput(text, what);
  if (!doc.is_object()) ThrowInputError(what, "", "", "a camera file holds one JSON object");
  for (const auto& [key, value] : doc.items()) {
    if (key != "eye" && key != "target" && key != "up" && key != "fov_deg" && key != "width" &&
        key != "height") {
      ThrowInputError(what, "", key, "unknown key (a camera has eye, target, up, fov_deg, width, height)");
    }
  }
  auto vector = [&](const char* key, Eigen::Vector3d* out) {
    if (!doc.contains(key)) ThrowInputError(what, "", key, "missing");
    const nlohmann::json& v = doc[key];
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number()) {
      ThrowInputError(what, "", key, "must be [x, y, z] (three numbers, metres)");
    }
    *out = Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
    if (!out->allFinite() || out->cwiseAbs().maxCoeff() > 1e9) {
      ThrowInputError(what, "", key, "must be finite and within 1e9 m");
    }
  };
  vector("eye", &view->eye_in_world);
  vector("target", &view->target_in_world);
  vector("up", &view->up_in_world);
  if (view->up_in_world.isZero(0)) ThrowInputError(what, "", "up", "must not be zero");
  if (doc.contains("fov_deg")) {
    if (!doc["fov_deg"].is_number()) ThrowInputError(what, "", "fov_deg", "must be a number (degrees)");
    view->field_of_view_deg = doc["fov_deg"].get<double>();
  }
  for (const auto& [key, out] :
       {std::pair{"width", &view->width_px}, std::pair{"height", &view->height_px}}) {
    if (!doc.contains(key)) continue;
    if (!doc[key].is_number_integer()) ThrowInputError(what, "", key, "must be an integer (pixels)");
    const int64_t value = doc[key].get<int64_t>();
    if (value < 16 || value > 16384) ThrowInputError(what, "", key, "must be in [16, 16384] pixels");
    *out = static_cast<int>(value);
  }
  try {
    view->Check();
  } catch (const OptionsError& e) {
    ThrowInputError(what, "", "", e.what());
  }
}

}  // namespace lidarshop
