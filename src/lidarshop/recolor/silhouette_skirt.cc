#include "lidarshop/recolor/silhouette_skirt.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/scan/ray_directions.h"

namespace lidarshop {

namespace {

// Per cell, metres: the width of the run of joined cells through it along its row (`along_rows`) or its column,
// when the run ends on both sides at a silhouette (a farther return, no return or the grid's border); +inf
// when either end meets a nearer surface (the object continues behind it) or the cell has no return.
cv::Mat SeenWidths(const Scan& scan, const RayDirections& rays, float ratio, bool along_rows) {
  const int lines = along_rows ? scan.rows : scan.cols, length = along_rows ? scan.cols : scan.rows;
  cv::Mat width(scan.rows, scan.cols, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  const auto at = [&](int line, int i) { return along_rows ? cv::Point(i, line) : cv::Point(line, i); };
  const auto valid = [&](int line, int i) { return scan.valid.at<uint8_t>(at(line, i)) != 0; };
  const auto range = [&](int line, int i) { return scan.range.at<float>(at(line, i)); };
  for (int line = 0; line < lines; ++line) {
    int i = 0;
    while (i < length) {
      if (!valid(line, i)) {
        ++i;
        continue;
      }
      int end = i;  // the run is [i, end]
      while (end + 1 < length && valid(line, end + 1) &&
             std::abs(range(line, end + 1) - range(line, end)) <=
                 ratio * std::min(range(line, end + 1), range(line, end)))
        ++end;
      // A silhouette on both sides: the neighbour beyond each end is farther or has no return.
      const bool before_free = i == 0 || !valid(line, i - 1) || range(line, i - 1) > range(line, i);
      const bool after_free =
          end + 1 == length || !valid(line, end + 1) || range(line, end + 1) > range(line, end);
      if (before_free && after_free) {
        const cv::Vec3f a = scan.point.at<cv::Vec3f>(at(line, i)),
                        b = scan.point.at<cv::Vec3f>(at(line, end));
        // The span between the end points and one cell's spacing at the run's range (the silhouette lies up to
        // a cell beyond): a run of one cell is a cell wide, not zero.
        const int beyond = i > 0 ? i - 1 : end + 1;
        float cell = std::numeric_limits<float>::infinity();
        if (beyond < length) {
          const cv::Point p = at(line, i), q = at(line, beyond);
          cell = range(line, i) * static_cast<float>(cv::norm(rays(p.y, p.x) - rays(q.y, q.x)));
        }
        const float seen = static_cast<float>(cv::norm(a - b)) + cell;
        for (int k = i; k <= end; ++k) width.at<float>(at(line, k)) = seen;
      }
      i = end + 1;
    }
  }
  return width;
}

}  // namespace

TriangleMesh SilhouetteSkirts(const Scan& scan, const SilhouetteSkirtOptions& options) {
  const RayDirections rays(scan);
  CheckScan(scan);
  cv::Mat seen_width;
  if (options.depth_per_width > 0 && options.depth_m > 0)
    cv::min(SeenWidths(scan, rays, static_cast<float>(options.max_range_jump_ratio), true),
            SeenWidths(scan, rays, static_cast<float>(options.max_range_jump_ratio), false), seen_width);
  const int rows = scan.rows, cols = scan.cols;
  const float ratio = static_cast<float>(options.max_range_jump_ratio);
  const auto valid = [&](int r, int c) { return scan.valid.at<uint8_t>(r, c) != 0; };
  const auto range = [&](int r, int c) { return scan.range.at<float>(r, c); };
  // The edge rule of ScanToMesh (both cells valid).
  const auto joined = [&](int r0, int c0, int r1, int c1) {
    const float a = range(r0, c0), b = range(r1, c1);
    return std::abs(a - b) <= ratio * std::min(a, b);
  };
  const Eigen::Matrix4d transform =
      options.world_frame ? scan.world_from_scanner : Eigen::Matrix4d::Identity();
  TriangleMesh mesh;
  const auto add_vertex = [&](const Eigen::Vector3f& p_in_scanner) {
    mesh.vertices.push_back(TransformPoint(transform, p_in_scanner));
    return static_cast<int>(mesh.vertices.size()) - 1;
  };

  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c + 1 < cols; ++c) {
      // Corners in cycle order a b d c (a b on row r, c d on row r + 1).
      const std::array<int, 4> cr = {r, r, r + 1, r + 1}, cc = {c, c + 1, c + 1, c};
      std::array<bool, 4> ok;
      int num_valid = 0;
      for (int i = 0; i < 4; ++i) num_valid += ok[i] = valid(cr[i], cc[i]);
      if (num_valid == 0) continue;
      // Layers: components of the joined edges (four sides and both diagonals).
      std::array<int, 4> layer = {0, 1, 2, 3};
      const auto find = [&](int i) {
        while (layer[i] != i) i = layer[i];
        return i;
      };
      bool full = num_valid == 4;  // the grid mesh fills the block (both triangles)
      for (int i = 0; i < 4; ++i) {
        for (int j = i + 1; j < 4; ++j) {
          const bool linked = ok[i] && ok[j] && joined(cr[i], cc[i], cr[j], cc[j]);
          if (linked) layer[find(j)] = find(i);
          if (!linked && !(i == 0 && j == 2)) full = false;  // ScanToMesh does not use the diagonal a-d
        }
      }
      if (full) continue;
      int farthest = -1;
      for (int i = 0; i < 4; ++i)
        if (ok[i] && (farthest < 0 || range(cr[i], cc[i]) > range(cr[farthest], cc[farthest]))) farthest = i;
      const bool open = num_valid < 4;  // a cell without a return: every layer's silhouette may grow
      std::array<bool, 4> done = {false, false, false, false};
      for (int seed = 0; seed < 4; ++seed) {
        if (!ok[seed] || done[find(seed)]) continue;
        const int root = find(seed);
        done[root] = true;
        if (!open && root == find(farthest)) continue;
        std::array<bool, 4> member;
        for (int i = 0; i < 4; ++i) member[i] = ok[i] && find(i) == root;
        // Each corner's cap vertex: its own point for members, else the layer carried along its ray.
        std::array<Eigen::Vector3f, 4> front, back;
        float wall_m = static_cast<float>(options.depth_m);
        if (!seen_width.empty())
          for (int i = 0; i < 4; ++i)
            if (member[i])
              wall_m = std::min(
                  wall_m, static_cast<float>(options.depth_per_width) * seen_width.at<float>(cr[i], cc[i]));
        bool usable = true;
        for (int i = 0; i < 4 && usable; ++i) {
          const cv::Vec3f d = rays(cr[i], cc[i]);
          Eigen::Vector3f direction(d[0], d[1], d[2]);
          float near_range = 0;
          float limit = std::numeric_limits<float>::infinity();  // a farther return on this ray
          if (member[i]) {
            const cv::Vec3f& p = scan.point.at<cv::Vec3f>(cr[i], cc[i]);
            front[i] = Eigen::Vector3f(p[0], p[1], p[2]);
            near_range = front[i].norm();
            direction = front[i] / std::max(near_range, 1e-6f);
          } else {
            if (!(direction.norm() > 0.5f)) {
              usable = false;
              break;
            }
            direction.normalize();
            // The member next to this corner (a side neighbour before the diagonal one), nearest first.
            int from = -1;
            for (int pass = 0; pass < 2 && from < 0; ++pass) {
              for (int j = 0; j < 4; ++j) {
                const bool side = (cr[i] == cr[j]) != (cc[i] == cc[j]);
                if (!member[j] || side != (pass == 0)) continue;
                if (from < 0 || range(cr[j], cc[j]) < range(cr[from], cc[from])) from = j;
              }
            }
            const int step_r = cr[i] - cr[from], step_c = cc[i] - cc[from];
            const float rf = range(cr[from], cc[from]);
            float extrapolated = rf;
            const int pr = cr[from] - step_r, pc = cc[from] - step_c;
            if (pr >= 0 && pr < rows && pc >= 0 && pc < cols && valid(pr, pc) &&
                joined(cr[from], cc[from], pr, pc))
              extrapolated = 2 * rf - range(pr, pc);
            extrapolated = std::clamp(extrapolated, rf / (1 + ratio), rf * (1 + ratio));
            if (ok[i]) {
              limit = range(cr[i], cc[i]) / (1 + ratio);
              extrapolated = std::min(extrapolated, limit);
            }
            near_range = extrapolated;
            front[i] = near_range * direction;
          }
          const float back_range = std::min(near_range + wall_m, limit);
          back[i] = std::max(back_range, near_range) * direction;
        }
        if (!usable) continue;
        std::array<int, 4> f;
        for (int i = 0; i < 4; ++i) f[i] = add_vertex(front[i]);
        // Facing the scanner like the grid mesh: (a, c, b) and (b, c, d) in cell order.
        mesh.triangles.emplace_back(f[0], f[3], f[1]);
        mesh.triangles.emplace_back(f[1], f[3], f[2]);
        if (options.depth_m > 0) {
          std::array<int, 4> b;
          for (int i = 0; i < 4; ++i) b[i] = add_vertex(back[i]);
          for (int i = 0; i < 4; ++i) {
            const int j = (i + 1) % 4;
            mesh.triangles.emplace_back(f[i], f[j], b[j]);
            mesh.triangles.emplace_back(f[i], b[j], b[i]);
          }
        }
      }
    }
  }
  return mesh;
}

}  // namespace lidarshop
