#include "lidarshop/io/render_view.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

// Grey of points when the scan has neither colour nor intensity.
constexpr uint8_t kPlainGrey = 200;

void PointViewOptions::Check() const {
  Validate(*this);
  CheckOption(
      eye_in_world.allFinite() && target_in_world.allFinite() && (target_in_world - eye_in_world).norm() > 0,
      "PointViewOptions: the eye and the target must be finite and distinct");
}

cv::Mat RenderPointView(const Scan& scan, const PointViewOptions& options) {
  options.Check();
  const Eigen::Vector3d forward = (options.target_in_world - options.eye_in_world).normalized();
  Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ());
  if (right.norm() < 1e-6) right = Eigen::Vector3d::UnitX();  // looking straight up or down
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

PointViewOptions SideView(const Scan& scan, const cv::Mat& region, double angle_deg) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int y = 0; y < scan.rows; ++y) {
    for (int x = 0; x < scan.cols; ++x) {
      if (!region.at<uint8_t>(y, x) || !scan.valid.at<uint8_t>(y, x)) continue;
      const cv::Vec3f p = scan.point.at<cv::Vec3f>(y, x);
      sum += (scan.world_from_scanner * Eigen::Vector4d(p[0], p[1], p[2], 1.0)).head<3>();
      ++count;
    }
  }
  const Eigen::Vector3d scanner = scan.world_from_scanner.block<3, 1>(0, 3);
  const Eigen::Vector3d centre =
      count > 0 ? Eigen::Vector3d(sum / count) : Eigen::Vector3d(scanner + Eigen::Vector3d::UnitY());
  const Eigen::Vector3d arm = scanner - centre;
  const Eigen::Vector3d turned = RotationFromEulerDegrees(Eigen::Vector3d(0, 0, angle_deg)) * arm;
  PointViewOptions view;
  view.eye_in_world = centre + turned;
  view.target_in_world = centre;
  return view;
}

}  // namespace lidarshop
