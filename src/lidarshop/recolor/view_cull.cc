#include "lidarshop/recolor/view_cull.h"

#include <algorithm>

#include "lidarshop/util/parallel.h"

namespace lidarshop::recolor_internal {

bool ViewPlanes::Outside(const Eigen::AlignedBox3f& box_world) const {
  if (box_world.isEmpty()) return true;
  const Eigen::Vector3d center = box_world.center().cast<double>() - center_world;
  const Eigen::Vector3d half = (0.5f * box_world.sizes()).cast<double>();
  for (int k = 0; k < count; ++k) {
    // The box's corner farthest along the plane's normal is still behind it.
    if (normal_world[k].dot(center) + normal_world[k].cwiseAbs().dot(half) < 0) return true;
  }
  return false;
}

ViewPlanes ImageViewPlanes(const Camera& camera) {
  ViewPlanes planes;
  if (camera.model != CameraModel::kPinhole) return planes;
  // x/z and y/z of the border's rays (a pinhole's unprojection keeps z = 1).
  constexpr int kSamples = 256;
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
  const double w = camera.width_px(), h = camera.height_px();
  const auto take = [&](double px, double py) {
    const Eigen::Vector3d ray = UnprojectPixel(camera.pinhole, Eigen::Vector2d(px, py));
    // The undistortion is a fixed-point iteration: where it did not converge (a strong distortion at the
    // corners), the ray does not project back to its pixel and the bound would be wrong: no bound then.
    Eigen::Vector2d back;
    if (!(ray.z() > 0) || !ray.allFinite() || !ProjectCameraPoint(camera.pinhole, ray, &back) ||
        (back - Eigen::Vector2d(px, py)).norm() > 0.25) {
      x_min = y_min = -INFINITY;  // no bound: keep everything
      return;
    }
    x_min = std::min(x_min, ray.x() / ray.z()), x_max = std::max(x_max, ray.x() / ray.z());
    y_min = std::min(y_min, ray.y() / ray.z()), y_max = std::max(y_max, ray.y() / ray.z());
  };
  for (int i = 0; i <= kSamples; ++i) {
    const double t = static_cast<double>(i) / kSamples;
    take(t * w, 0), take(t * w, h), take(0, t * h), take(w, t * h);
  }
  if (!std::isfinite(x_min) || !std::isfinite(y_min) || !std::isfinite(x_max) || !std::isfinite(y_max))
    return planes;
  // The margin: the border may bend outward between samples (a distortion), and the rasterizer's box padding.
  const double mx = 0.02 * (x_max - x_min) + 1e-6, my = 0.02 * (y_max - y_min) + 1e-6;
  x_min -= mx, x_max += mx, y_min -= my, y_max += my;
  // Inside: x_min·z ≤ x ≤ x_max·z and y_min·z ≤ y ≤ y_max·z.
  const Eigen::Vector3d normals[4] = {{1, 0, -x_min}, {-1, 0, x_max}, {0, 1, -y_min}, {0, -1, y_max}};
  const Eigen::Matrix3d rotation = camera.world_from_camera.topLeftCorner<3, 3>();
  planes.count = 4;
  planes.center_world = camera.center_in_world();
  for (int k = 0; k < 4; ++k) {
    planes.normal[k] = normals[k].cast<float>();
    planes.normal_world[k] = rotation * normals[k];
  }
  return planes;
}

std::vector<Eigen::AlignedBox3f> TriangleBlockBoxes(const TriangleMesh& mesh, int block_triangles) {
  const int64_t triangles = static_cast<int64_t>(mesh.triangles.size());
  const int64_t blocks = (triangles + block_triangles - 1) / block_triangles;
  std::vector<Eigen::AlignedBox3f> boxes(blocks);
  ParallelFor(
      blocks,
      [&](int64_t b) {
        Eigen::AlignedBox3f box;  // empty
        const int64_t end = std::min(triangles, (b + 1) * block_triangles);
        for (int64_t f = b * block_triangles; f < end; ++f) {
          for (int k = 0; k < 3; ++k) box.extend(mesh.vertices[mesh.triangles[f][k]]);
        }
        boxes[b] = box;
      },
      64);
  return boxes;
}

CellBoxes CellBoxesOf(const Scan& scan, int segment_cols) {
  CellBoxes out;
  out.segment_cols = segment_cols;
  out.segments = (scan.cols + segment_cols - 1) / segment_cols;
  out.boxes.resize(static_cast<size_t>(scan.rows) * out.segments);
  out.valid.assign(out.boxes.size(), 0);
  const Eigen::Matrix3f rotation = scan.world_from_scanner.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f translation = scan.world_from_scanner.topRightCorner<3, 1>().cast<float>();
  ParallelFor(scan.rows, [&](int64_t row) {
    const int r = static_cast<int>(row);
    const uint8_t* valid = scan.valid.ptr<uint8_t>(r);
    const cv::Vec3f* point = scan.point.ptr<cv::Vec3f>(r);
    for (int s = 0; s < out.segments; ++s) {
      Eigen::AlignedBox3f box;
      int32_t count = 0;
      for (int c = s * segment_cols; c < std::min(scan.cols, (s + 1) * segment_cols); ++c) {
        if (!valid[c]) continue;
        box.extend(rotation * Eigen::Vector3f(point[c][0], point[c][1], point[c][2]) + translation);
        ++count;
      }
      // Float rounding of the transform (the visibility test projects in double): grow by a millimetre.
      if (count > 0)
        box.extend(box.min() - Eigen::Vector3f::Constant(1e-3f)),
            box.extend(box.max() + Eigen::Vector3f::Constant(1e-3f));
      out.boxes[static_cast<size_t>(r) * out.segments + s] = box;
      out.valid[static_cast<size_t>(r) * out.segments + s] = count;
    }
  });
  return out;
}

}  // namespace lidarshop::recolor_internal
