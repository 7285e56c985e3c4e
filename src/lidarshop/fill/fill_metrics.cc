#include "lidarshop/fill/fill_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

bool Valid(const Scan& scan, int y, int x) {
  return y >= 0 && y < scan.rows && x >= 0 && x < scan.cols && scan.valid.at<uint8_t>(y, x) != 0;
}

Eigen::Vector3f PointAt(const Scan& scan, int y, int x) {
  const cv::Vec3f p = scan.point.at<cv::Vec3f>(y, x);
  return {p[0], p[1], p[2]};
}

float TruthRange(const Scan& truth, int y, int x) {
  if (!truth.true_range.empty() && truth.true_range.at<float>(y, x) > 0)
    return truth.true_range.at<float>(y, x);
  return truth.range.at<float>(y, x);
}

// The truth's noise-free point of a cell (its own ray at the true range).
Eigen::Vector3f TruePointAt(const Scan& truth, int y, int x) {
  if (truth.direction.empty()) return PointAt(truth, y, x);
  const cv::Vec3f d = truth.direction.at<cv::Vec3f>(y, x) * TruthRange(truth, y, x);
  return {d[0], d[1], d[2]};
}

// Distance from p to the triangle abc (the closest point by Voronoi regions, Ericson 2005, 5.1.5).
double PointTriangleDistance(const Eigen::Vector3f& p, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                             const Eigen::Vector3f& c) {
  const Eigen::Vector3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  const Eigen::Vector3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + ab * (d1 / (d1 - d3)))).norm();
  const Eigen::Vector3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + ac * (d2 / (d2 - d6)))).norm();
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).norm();
  const float denom = 1.0f / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

// Distance from p to the truth's surface around cell (y, x): the triangles of the truth's grid within
// `reach` cells, leaving out those across a depth jump (a silhouette is no surface). At grazing incidence
// the rows of a far ground lie a metre apart, so the nearest truth *point* can be far from a point lying on
// the true surface between them; this measures to the surface itself. Infinity when there is none.
double LocalSurfaceDistance(const Scan& truth, int y, int x, const Eigen::Vector3f& p, int reach) {
  constexpr float kJumpRatio = 1.2f;
  double best = std::numeric_limits<double>::infinity();
  for (int qy = y - reach; qy < y + reach; ++qy) {
    for (int qx = x - reach; qx < x + reach; ++qx) {
      if (!Valid(truth, qy, qx) || !Valid(truth, qy, qx + 1) || !Valid(truth, qy + 1, qx) ||
          !Valid(truth, qy + 1, qx + 1))
        continue;
      const float r[4] = {TruthRange(truth, qy, qx), TruthRange(truth, qy, qx + 1),
                          TruthRange(truth, qy + 1, qx), TruthRange(truth, qy + 1, qx + 1)};
      if (*std::max_element(r, r + 4) > kJumpRatio * *std::min_element(r, r + 4)) continue;
      const Eigen::Vector3f a = TruePointAt(truth, qy, qx), b = TruePointAt(truth, qy, qx + 1),
                            c = TruePointAt(truth, qy + 1, qx), d = TruePointAt(truth, qy + 1, qx + 1);
      best = std::min({best, PointTriangleDistance(p, a, b, d), PointTriangleDistance(p, a, d, c)});
    }
  }
  return best;
}

}  // namespace

FillMetrics MeasureFill(const Scan& filled, const Scan& truth_in, const cv::Mat& hole_in,
                        const FillMetricsOptions& options) {
  // The truth's rays as an image (a truth read from a file may hold only its grid: ray_directions.h).
  Scan truth = truth_in;
  truth.direction = DirectionImage(truth_in);
  if (filled.rows != truth.rows || filled.cols != truth.cols || hole_in.rows != truth.rows ||
      hole_in.cols != truth.cols) {
    throw InputError(fmt::format("MeasureFill: the fill ({} x {}), truth ({} x {}) and hole ({} x {}) differ",
                                 filled.cols, filled.rows, truth.cols, truth.rows, hole_in.cols,
                                 hole_in.rows));
  }
  const cv::Mat hole = hole_in != 0;
  FillMetrics m;
  m.hole_cells = cv::countNonZero(hole);
  m.floating_cells = cv::Mat::zeros(hole.size(), CV_8U);
  if (m.hole_cells == 0) return m;

  std::vector<Eigen::Vector3f> truth_points;
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      if (Valid(truth, y, x)) truth_points.push_back(PointAt(truth, y, x));
    }
  }
  const PointKdTree tree(std::move(truth_points));
  constexpr int kSurfaceReach = 2;  // cells: the truth's triangles around a filled cell's own ray

  double sum_sq = 0, sum_abs = 0, color_sq = 0, normal_deg = 0;
  int64_t within = 0, same_return = 0, synthesized = 0, floating = 0, normals = 0, color_values = 0;
  const bool color = filled.has_color() && truth.has_color();
  // Plane-fit normals of the filled points over a (2r+1)² window of the grid (pointset/normals.h).
  cv::Mat filled_normals;
  if (!truth.normal.empty() && filled.CountValid() >= 3) {
    NormalOptions normal_options;
    normal_options.window_cells = options.normal_window_radius;
    filled_normals = EstimateGridNormals(filled, normal_options).normal;
  }
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      if (!hole.at<uint8_t>(y, x)) continue;
      const bool f = Valid(filled, y, x), t = Valid(truth, y, x);
      if (f == t) ++same_return;
      if (f) {
        ++synthesized;
        const Eigen::Vector3f p = PointAt(filled, y, x);
        const NearestResult nearest = tree.NearestWithin(p, static_cast<float>(options.floating_m));
        if (!nearest.found() && LocalSurfaceDistance(truth, y, x, p, kSurfaceReach) > options.floating_m) {
          ++floating;
          m.floating_cells.at<uint8_t>(y, x) = 255;
        }
      }
      if (!f || !t) continue;
      ++m.compared_cells;
      const double error = static_cast<double>(filled.range.at<float>(y, x)) - TruthRange(truth, y, x);
      sum_sq += error * error;
      sum_abs += std::abs(error);
      if (std::abs(error) <= options.within_m) ++within;
      if (color) {
        const cv::Vec3b a = filled.color.at<cv::Vec3b>(y, x), b = truth.color.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) color_sq += (a[c] - b[c]) * (a[c] - b[c]);
        color_values += 3;
      }
      if (!filled_normals.empty()) {
        const cv::Vec3f fn = filled_normals.at<cv::Vec3f>(y, x);
        const Eigen::Vector3f n(fn[0], fn[1], fn[2]);
        const cv::Vec3f tn = truth.normal.at<cv::Vec3f>(y, x);
        const Eigen::Vector3f true_normal(tn[0], tn[1], tn[2]);
        if (n.norm() > 0.5f && true_normal.norm() > 0.5f) {
          const double cosine = std::min(1.0, std::abs(static_cast<double>(n.dot(true_normal.normalized()))));
          normal_deg += std::acos(cosine) * 180.0 / M_PI;
          ++normals;
        }
      }
    }
  }
  if (m.compared_cells > 0) {
    m.range_rmse_mm = 1000.0 * std::sqrt(sum_sq / static_cast<double>(m.compared_cells));
    m.range_mae_mm = 1000.0 * sum_abs / static_cast<double>(m.compared_cells);
    m.within_share = static_cast<double>(within) / static_cast<double>(m.compared_cells);
  }
  if (normals > 0) m.normal_error_deg = normal_deg / static_cast<double>(normals);
  if (synthesized > 0) m.floating_share = static_cast<double>(floating) / static_cast<double>(synthesized);
  m.return_accuracy = static_cast<double>(same_return) / static_cast<double>(m.hole_cells);
  if (color_values > 0) {
    const double mse = color_sq / static_cast<double>(color_values);
    m.color_psnr_db = mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 99.0;
  }

  // Seams: range jumps across the hole boundary against those just outside it.
  cv::Mat band;
  const int size = 2 * options.seam_band_cells + 1;
  cv::dilate(hole, band, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size)));
  band &= ~hole;
  double seam = 0, outside = 0;
  int64_t seam_edges = 0, outside_edges = 0;
  for (int y = 0; y < filled.rows; ++y) {
    for (int x = 0; x < filled.cols; ++x) {
      for (const auto& [dy, dx] : {std::pair{0, 1}, std::pair{1, 0}}) {
        const int ny = y + dy, nx = x + dx;
        if (!Valid(filled, y, x) || !Valid(filled, ny, nx)) continue;
        const double jump = std::abs(filled.range.at<float>(y, x) - filled.range.at<float>(ny, nx));
        const bool a = hole.at<uint8_t>(y, x) != 0, b = hole.at<uint8_t>(ny, nx) != 0;
        if (a != b) {
          seam += jump;
          ++seam_edges;
        } else if (!a && band.at<uint8_t>(y, x) && band.at<uint8_t>(ny, nx)) {
          outside += jump;
          ++outside_edges;
        }
      }
    }
  }
  if (seam_edges > 0) m.seam_mm = 1000.0 * seam / static_cast<double>(seam_edges);
  if (outside_edges > 0) m.seam_outside_mm = 1000.0 * outside / static_cast<double>(outside_edges);
  return m;
}

}  // namespace lidarshop
