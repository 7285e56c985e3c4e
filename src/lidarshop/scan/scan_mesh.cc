#include "lidarshop/scan/scan_mesh.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void ScanMeshOptions::Check() const { Validate(*this); }

TriangleMesh ScanToMesh(const Scan& scan, const ScanMeshOptions& options) {
  options.Check();
  CheckScan(scan);
  const int rows = scan.rows, cols = scan.cols;
  const float ratio = static_cast<float>(options.max_range_jump_ratio);
  const float max_edge_sq = static_cast<float>(options.max_edge_m * options.max_edge_m);
  auto valid = [&](int r, int c) { return scan.valid.at<uint8_t>(r, c) != 0; };
  auto range = [&](int r, int c) { return scan.range.at<float>(r, c); };
  auto joined = [&](int r0, int c0, int r1, int c1) {
    const float a = range(r0, c0), b = range(r1, c1);
    if (std::abs(a - b) > ratio * std::min(a, b)) return false;
    if (max_edge_sq <= 0.0f) return true;
    const cv::Vec3f d = scan.point.at<cv::Vec3f>(r0, c0) - scan.point.at<cv::Vec3f>(r1, c1);
    return d.dot(d) <= max_edge_sq;
  };
  // Triangles over cell indices first, then compact the vertices that are used.
  // Rows in parallel, each into its own list, joined in row order (the same mesh on any thread count).
  std::vector<std::vector<Eigen::Vector3i>> row_triangles(std::max(0, rows - 1));
  ParallelFor(rows - 1 > 0 ? rows - 1 : 0, [&](int64_t row) {
    const int r = static_cast<int>(row);
    std::vector<Eigen::Vector3i>& cell_triangles = row_triangles[row];
    for (int c = 0; c + 1 < cols; ++c) {
      const bool va = valid(r, c), vb = valid(r, c + 1), vc = valid(r + 1, c), vd = valid(r + 1, c + 1);
      const int a = r * cols + c, b = a + 1, cc = a + cols, d = cc + 1;
      // a b   (row r, the upper one)
      // c d
      const bool bc = vb && vc && joined(r, c + 1, r + 1, c);
      if (va && bc && joined(r, c, r + 1, c) && joined(r, c, r, c + 1)) cell_triangles.emplace_back(a, cc, b);
      if (vd && bc && joined(r, c + 1, r + 1, c + 1) && joined(r + 1, c, r + 1, c + 1)) {
        cell_triangles.emplace_back(b, cc, d);
      }
    }
  });
  std::vector<Eigen::Vector3i> cell_triangles;
  {
    size_t total = 0;
    for (const auto& row : row_triangles) total += row.size();
    cell_triangles.reserve(total);
    for (auto& row : row_triangles) {
      cell_triangles.insert(cell_triangles.end(), row.begin(), row.end());
      std::vector<Eigen::Vector3i>().swap(row);
    }
  }
  std::vector<int> vertex_of_cell(static_cast<size_t>(rows) * cols, -1);
  TriangleMesh mesh;
  const bool with_color = scan.has_color(), with_normal = !scan.normal.empty();
  const Eigen::Matrix4d transform =
      options.world_frame ? scan.world_from_scanner : Eigen::Matrix4d::Identity();
  const Eigen::Matrix3f rotation = transform.topLeftCorner<3, 3>().cast<float>();
  for (auto& triangle : cell_triangles) {
    for (int corner = 0; corner < 3; ++corner) {
      const int cell = triangle[corner];
      if (vertex_of_cell[cell] < 0) {
        const int r = cell / cols, c = cell % cols;
        vertex_of_cell[cell] = static_cast<int>(mesh.vertices.size());
        const cv::Vec3f& p = scan.point.at<cv::Vec3f>(r, c);
        mesh.vertices.push_back(TransformPoint(transform, Eigen::Vector3f(p[0], p[1], p[2])));
        if (with_color) {
          const cv::Vec3b& rgb = scan.color.at<cv::Vec3b>(r, c);
          mesh.vertex_colors.emplace_back(rgb[0], rgb[1], rgb[2]);
        }
        if (with_normal) {
          const cv::Vec3f& n = scan.normal.at<cv::Vec3f>(r, c);
          mesh.vertex_normals.push_back(rotation * Eigen::Vector3f(n[0], n[1], n[2]));
        }
      }
      triangle[corner] = vertex_of_cell[cell];
    }
  }
  mesh.triangles = std::move(cell_triangles);
  return mesh;
}

}  // namespace lidarshop
