#include "lidarshop/render/render_shading.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

namespace lidarshop {
namespace {

// The surface seen in an orthographic view, as unit normals in the view's frame (right, up in the picture,
// towards the viewer; CV_32FC3, zero where no point is): the cells' heights towards the viewer smoothed over
// about a square's side (the squares of one point are flat, and their steps are not the surface's), then
// central differences in metres.
cv::Mat ViewNormals(const PictureLayout& layout) {
  const Scan& cells = layout.cells;
  const Eigen::Vector3d toward = TowardViewer(layout.view);
  cv::Mat height(cells.rows, cells.cols, CV_32F, cv::Scalar(0));
  cv::Mat weight(cells.rows, cells.cols, CV_32F, cv::Scalar(0));
  for (int row = 0; row < cells.rows; ++row) {
    for (int col = 0; col < cells.cols; ++col) {
      if (!cells.valid.at<uint8_t>(row, col)) continue;
      height.at<float>(row, col) = static_cast<float>(toward.dot(WorldPointOfCell(cells, row, col)));
      weight.at<float>(row, col) = 1.0f;
    }
  }
  // Heights relative to their mean keep float precision (a LAS file's 400 m elevations).
  const double mean = cv::sum(height)[0] / std::max(1.0, cv::sum(weight)[0]);
  cv::subtract(height, cv::Scalar(mean), height, weight > 0);
  const double sigma = std::max(1.0, 0.5 * layout.splat_px);
  cv::Mat height_sum, weight_sum;
  cv::GaussianBlur(height, height_sum, cv::Size(), sigma);
  cv::GaussianBlur(weight, weight_sum, cv::Size(), sigma);
  const cv::Mat smooth = height_sum / cv::max(weight_sum, 1e-6);
  cv::Mat normals(cells.rows, cells.cols, CV_32FC3, cv::Scalar::all(0));
  for (int row = 0; row < cells.rows; ++row) {
    for (int col = 0; col < cells.cols; ++col) {
      if (!cells.valid.at<uint8_t>(row, col)) continue;
      auto at = [&](int r, int c) {
        r = std::clamp(r, 0, cells.rows - 1);
        c = std::clamp(c, 0, cells.cols - 1);
        return weight_sum.at<float>(r, c) > 0.05f ? smooth.at<float>(r, c) : smooth.at<float>(row, col);
      };
      const double d_right = (at(row, col + 1) - at(row, col - 1)) / (2 * layout.pixel_width);
      const double d_up = (at(row - 1, col) - at(row + 1, col)) / (2 * layout.pixel_height);
      const Eigen::Vector3d n = Eigen::Vector3d(-d_right, -d_up, 1.0).normalized();
      normals.at<cv::Vec3f>(row, col) =
          cv::Vec3f(static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z()));
    }
  }
  return normals;
}

}  // namespace

cv::Mat OrthographicNormals(const PictureLayout& layout) {
  const Eigen::Vector3d toward = TowardViewer(layout.view);
  const Eigen::Vector3d up =
      layout.view == PictureView::kTop ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d world_from_view;
  world_from_view << up.cross(toward), up, toward;
  const Eigen::Matrix3d scanner_from_view =
      layout.cells.world_from_scanner.topLeftCorner<3, 3>().transpose() * world_from_view;
  cv::Mat normals = ViewNormals(layout);
  for (auto it = normals.begin<cv::Vec3f>(); it != normals.end<cv::Vec3f>(); ++it) {
    if (*it == cv::Vec3f(0, 0, 0)) continue;
    const Eigen::Vector3d n = scanner_from_view * Eigen::Vector3d((*it)[0], (*it)[1], (*it)[2]);
    *it = cv::Vec3f(static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z()));
  }
  return normals;
}

void Hillshade(const PictureLayout& layout, cv::Mat* image) {
  constexpr double kAzimuthRad = 315.0 * M_PI / 180.0, kAltitudeRad = 45.0 * M_PI / 180.0;
  const Eigen::Vector3d light(std::cos(kAltitudeRad) * std::sin(kAzimuthRad),
                              std::cos(kAltitudeRad) * std::cos(kAzimuthRad), std::sin(kAltitudeRad));
  const cv::Mat normals = ViewNormals(layout);
  for (int row = 0; row < normals.rows; ++row) {
    for (int col = 0; col < normals.cols; ++col) {
      const cv::Vec3f n = normals.at<cv::Vec3f>(row, col);
      if (n == cv::Vec3f(0, 0, 0)) continue;
      const double shade = std::max(0.0, n[0] * light.x() + n[1] * light.y() + n[2] * light.z()) / light.z();
      const double factor = std::min(1.3, 0.25 + 0.75 * shade);
      cv::Vec3b& pixel = image->at<cv::Vec3b>(row, col);
      for (int k = 0; k < 3; ++k) pixel[k] = cv::saturate_cast<uint8_t>(pixel[k] * factor);
    }
  }
}

}  // namespace lidarshop
