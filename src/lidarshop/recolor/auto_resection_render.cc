#include "lidarshop/recolor/auto_resection_render.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"

namespace lidarshop::auto_resection_internal {
namespace {

// The median angle between neighbouring columns and rows of the scan's grid, radians.
double CellAngleRad(const Scan& scan) {
  const ScanGrid grid = GridOf(scan);
  std::vector<double> steps;
  for (size_t i = 1; i < grid.azimuth_rad.size(); ++i)
    steps.push_back(std::abs(grid.azimuth_rad[i] - grid.azimuth_rad[i - 1]));
  for (size_t i = 1; i < grid.elevation_rad.size(); ++i)
    steps.push_back(std::abs(grid.elevation_rad[i] - grid.elevation_rad[i - 1]));
  std::erase_if(steps, [](double s) { return !(s > 1e-7) || s > 0.2; });
  const double step = Median(steps);
  return step > 0 ? step : 0.2 / kDegPerRad;
}

}  // namespace

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

ScanSamples SamplesOf(const Scan& scan, const std::string& what, Shade shade) {
  cv::Mat grey;
  const bool use_color = scan.has_color() && (shade == Shade::kColorElseIntensity || !scan.has_intensity());
  if (use_color) {
    cv::cvtColor(scan.color, grey, cv::COLOR_RGB2GRAY);
  } else if (scan.has_intensity()) {
    scan.intensity.convertTo(grey, CV_8U, 255.0);
  } else {
    ThrowInputError(what, "", "color", "automatic resection needs a scan with colour or intensity");
  }
  ScanSamples samples;
  samples.cell_angle_rad = CellAngleRad(scan);
  samples.scanner_in_world = scan.world_from_scanner.topRightCorner<3, 1>();
  samples.index = cv::Mat(scan.rows, scan.cols, CV_32S, cv::Scalar(-1));
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      if (!scan.valid.at<uint8_t>(r, c)) continue;
      const Eigen::Vector3d point = WorldPointOfCell(scan, r, c);
      if (!point.allFinite()) continue;
      samples.index.at<int32_t>(r, c) = static_cast<int32_t>(samples.point_in_world.size());
      samples.point_in_world.push_back(point);
      samples.grey.push_back(grey.at<uint8_t>(r, c));
      samples.range_m.push_back(static_cast<float>((point - samples.scanner_in_world).norm()));
    }
  }
  return samples;
}

// The scan's grid mesh (two triangles per 2 x 2 cells whose returns lie on one surface; three returns make
// one) rasterized with a z-buffer; grey and point interpolated perspective-correctly. Vertices are projected
// with the camera's distortion and the triangles are straight in the image: they are about a pixel wide.
View Render(const ScanSamples& samples, const PinholeCamera& camera) {
  View view;
  view.camera = camera;
  const int width = camera.width_px, height = camera.height_px;
  cv::Mat grey(height, width, CV_32F, cv::Scalar(0));
  view.point_from_eye = cv::Mat(height, width, CV_32FC3, cv::Scalar::all(0));
  view.depth = cv::Mat(height, width, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  const Eigen::Matrix3d camera_from_world = camera.world_from_camera.topLeftCorner<3, 3>().transpose();
  const Eigen::Vector3d eye = camera.center_in_world();
  const size_t n = samples.point_in_world.size();
  // Per sample: pixel (x, y) and depth z (z <= 0: not projected).
  std::vector<Eigen::Vector3d> projected(n);
  std::vector<Eigen::Vector3f> from_eye(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = samples.point_in_world[i] - eye;
    from_eye[i] = d.cast<float>();
    const Eigen::Vector3d point_in_camera = camera_from_world * d;
    Eigen::Vector2d pixel;
    if (point_in_camera.z() < 0.05 || !ProjectCameraPoint(camera, point_in_camera, &pixel)) {
      projected[i] = Eigen::Vector3d(0, 0, -1);
      continue;
    }
    projected[i] = Eigen::Vector3d(pixel.x(), pixel.y(), point_in_camera.z());
  }
  const auto triangle = [&](int a, int b, int c) {
    const Eigen::Vector3d &pa = projected[a], &pb = projected[b], &pc = projected[c];
    if (pa.z() <= 0 || pb.z() <= 0 || pc.z() <= 0) return;
    const float r_min = std::min({samples.range_m[a], samples.range_m[b], samples.range_m[c]}),
                r_max = std::max({samples.range_m[a], samples.range_m[b], samples.range_m[c]});
    if (r_max > kMaxRangeRatio * r_min) return;
    // Triangles seen edge-on or stretched over many pixels are depth edges the range test missed.
    const double area = (pb.x() - pa.x()) * (pc.y() - pa.y()) - (pc.x() - pa.x()) * (pb.y() - pa.y());
    if (std::abs(area) < 1e-9) return;
    const double min_x = std::min({pa.x(), pb.x(), pc.x()}), max_x = std::max({pa.x(), pb.x(), pc.x()});
    const double min_y = std::min({pa.y(), pb.y(), pc.y()}), max_y = std::max({pa.y(), pb.y(), pc.y()});
    if (max_x - min_x > 16 || max_y - min_y > 16) return;
    const int x0 = std::max(0, static_cast<int>(std::ceil(min_x - 0.5))),
              x1 = std::min(width - 1, static_cast<int>(std::floor(max_x - 0.5)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(min_y - 0.5))),
              y1 = std::min(height - 1, static_cast<int>(std::floor(max_y - 0.5)));
    for (int y = y0; y <= y1; ++y) {
      const double py = y + 0.5;
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5;
        // Barycentric weights (screen space), then perspective-correct ones (divided by depth).
        double wa = ((pb.x() - px) * (pc.y() - py) - (pc.x() - px) * (pb.y() - py)) / area;
        double wb = ((pc.x() - px) * (pa.y() - py) - (pa.x() - px) * (pc.y() - py)) / area;
        double wc = 1 - wa - wb;
        if (wa < -1e-9 || wb < -1e-9 || wc < -1e-9) continue;
        wa /= pa.z(), wb /= pb.z(), wc /= pc.z();
        const double sum = wa + wb + wc;
        const float z = static_cast<float>(1 / sum);
        float& depth = view.depth.at<float>(y, x);
        if (z >= depth) continue;
        depth = z;
        wa /= sum, wb /= sum, wc /= sum;
        grey.at<float>(y, x) =
            static_cast<float>(wa * samples.grey[a] + wb * samples.grey[b] + wc * samples.grey[c]);
        const Eigen::Vector3f p = static_cast<float>(wa) * from_eye[a] +
                                  static_cast<float>(wb) * from_eye[b] + static_cast<float>(wc) * from_eye[c];
        view.point_from_eye.at<cv::Vec3f>(y, x) = cv::Vec3f(p.x(), p.y(), p.z());
      }
    }
  };
  const cv::Mat& index = samples.index;
  for (int r = 0; r + 1 < index.rows; ++r) {
    for (int c = 0; c + 1 < index.cols; ++c) {
      const int a = index.at<int32_t>(r, c), b = index.at<int32_t>(r, c + 1), d = index.at<int32_t>(r + 1, c),
                e = index.at<int32_t>(r + 1, c + 1);
      const int count = (a >= 0) + (b >= 0) + (d >= 0) + (e >= 0);
      if (count == 4) {
        triangle(a, b, d), triangle(b, e, d);
      } else if (count == 3) {
        if (a < 0) triangle(b, e, d);
        if (b < 0) triangle(a, e, d);
        if (d < 0) triangle(a, b, e);
        if (e < 0) triangle(a, b, d);
      }
    }
  }
  grey.convertTo(view.grey, CV_8U);
  return view;
}

PinholeCamera Scaled(const PinholeCamera& camera, int width_px, int height_px) {
  PinholeCamera out = camera;
  const double sx = static_cast<double>(width_px) / camera.width_px,
               sy = static_cast<double>(height_px) / camera.height_px;
  out.width_px = width_px, out.height_px = height_px;
  out.fx_px *= sx, out.skew_px *= sx, out.cx_px *= sx;
  out.fy_px *= sy, out.cy_px *= sy;
  return out;
}

void SetPose(const cv::Mat& rvec, const cv::Mat& tvec, PinholeCamera* camera) {
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  Eigen::Matrix3d r;
  cv::cv2eigen(cv::Mat(rotation), r);
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  camera->world_from_camera.setIdentity();
  camera->world_from_camera.topLeftCorner<3, 3>() = r.transpose();
  camera->world_from_camera.topRightCorner<3, 1>() = -r.transpose() * t;
}

}  // namespace lidarshop::auto_resection_internal
