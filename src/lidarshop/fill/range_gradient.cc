#include "lidarshop/fill/range_gradient.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/poisson/operators.h"

namespace lidarshop::fill_internal {

RangeGradient OneSidedRangeGradient(const cv::Mat& range, const cv::Mat& usable) {
  const int rows = range.rows, cols = range.cols;
  RangeGradient g{cv::Mat(rows, cols, CV_32F, cv::Scalar(0)), cv::Mat(rows, cols, CV_32F, cv::Scalar(0))};
  auto ok = [&](int y, int x) {
    return y >= 0 && y < rows && x >= 0 && x < cols && usable.at<uint8_t>(y, x) != 0;
  };
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      if (!ok(y, x)) continue;
      const float r = range.at<float>(y, x);
      if (ok(y, x + 1)) {
        g.gx.at<float>(y, x) = range.at<float>(y, x + 1) - r;
      } else if (ok(y, x - 1)) {
        g.gx.at<float>(y, x) = r - range.at<float>(y, x - 1);
      }
      if (ok(y + 1, x)) {
        g.gy.at<float>(y, x) = range.at<float>(y + 1, x) - r;
      } else if (ok(y - 1, x)) {
        g.gy.at<float>(y, x) = r - range.at<float>(y - 1, x);
      }
    }
  }
  return g;
}

cv::Mat NearestKnownCell(const cv::Mat& hole) {
  const int rows = hole.rows, cols = hole.cols;
  cv::Mat nearest(rows, cols, CV_32SC2, cv::Scalar(-1, -1));
  std::deque<cv::Point> queue;  // (x = col, y = row)
  // Seeds: known cells next to the hole, in raster order.
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      if (hole.at<uint8_t>(y, x) != 0) continue;
      const bool borders =
          (x > 0 && hole.at<uint8_t>(y, x - 1)) || (x + 1 < cols && hole.at<uint8_t>(y, x + 1)) ||
          (y > 0 && hole.at<uint8_t>(y - 1, x)) || (y + 1 < rows && hole.at<uint8_t>(y + 1, x));
      if (!borders) continue;
      nearest.at<cv::Vec2i>(y, x) = cv::Vec2i(y, x);
      queue.emplace_back(x, y);
    }
  }
  constexpr int kDx[4] = {-1, 1, 0, 0}, kDy[4] = {0, 0, -1, 1};
  while (!queue.empty()) {
    const cv::Point p = queue.front();
    queue.pop_front();
    const cv::Vec2i from = nearest.at<cv::Vec2i>(p.y, p.x);
    for (int k = 0; k < 4; ++k) {
      const int nx = p.x + kDx[k], ny = p.y + kDy[k];
      if (nx < 0 || nx >= cols || ny < 0 || ny >= rows || hole.at<uint8_t>(ny, nx) == 0) continue;
      cv::Vec2i& to = nearest.at<cv::Vec2i>(ny, nx);
      if (to[0] >= 0) continue;
      to = from;
      queue.emplace_back(nx, ny);
    }
  }
  // Known cells point to nothing.
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      if (hole.at<uint8_t>(y, x) == 0) nearest.at<cv::Vec2i>(y, x) = cv::Vec2i(-1, -1);
    }
  }
  return nearest;
}

EdgeMasks DepthJumps(const cv::Mat& range, const cv::Mat& usable, double ratio) {
  const int rows = range.rows, cols = range.cols;
  EdgeMasks jumps{cv::Mat(rows, cols, CV_8U, cv::Scalar(0)), cv::Mat(rows, cols, CV_8U, cv::Scalar(0))};
  if (ratio <= 0) return jumps;
  auto jump = [&](int y, int x, int ny, int nx) {
    if (ny >= rows || nx >= cols || !usable.at<uint8_t>(y, x) || !usable.at<uint8_t>(ny, nx)) return false;
    const float a = range.at<float>(y, x), b = range.at<float>(ny, nx);
    return std::abs(a - b) > ratio * std::min(a, b);
  };
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      if (jump(y, x, y, x + 1)) jumps.right.at<uint8_t>(y, x) = 255;
      if (jump(y, x, y + 1, x)) jumps.down.at<uint8_t>(y, x) = 255;
    }
  }
  return jumps;
}

namespace {

bool Cut(const cv::Mat& mask, int y, int x) { return !mask.empty() && mask.at<uint8_t>(y, x) != 0; }

}  // namespace

cv::Mat GuidanceDivergence(const cv::Mat& gx_in, const cv::Mat& gy_in, const cv::Mat& no_data,
                           const EdgeMasks& cuts) {
  cv::Mat gx, gy;
  gx_in.convertTo(gx, CV_64F);
  gy_in.convertTo(gy, CV_64F);
  const int rows = gx.rows, cols = gx.cols;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const bool here = no_data.at<uint8_t>(y, x) != 0;
      if (here || x + 1 >= cols || no_data.at<uint8_t>(y, x + 1) != 0 || Cut(cuts.right, y, x))
        gx.at<double>(y, x) = 0.0;
      if (here || y + 1 >= rows || no_data.at<uint8_t>(y + 1, x) != 0 || Cut(cuts.down, y, x))
        gy.at<double>(y, x) = 0.0;
    }
  }
  return BackwardDivergence(gx, gy);
}

cv::Mat UnanchoredCells(const cv::Mat& domain, const cv::Mat& anchor, const EdgeMasks& cuts) {
  const int rows = domain.rows, cols = domain.cols;
  // Breadth-first from every domain cell next to an anchor through uncut edges;
  // what is not reached is cut off.
  cv::Mat reached(rows, cols, CV_8U, cv::Scalar(0));
  std::deque<cv::Point> queue;
  auto linked = [&](int y, int x, int ny, int nx) {
    if (ny < 0 || ny >= rows || nx < 0 || nx >= cols) return false;
    if (ny == y) return !Cut(cuts.right, y, std::min(x, nx));
    return !Cut(cuts.down, std::min(y, ny), x);
  };
  constexpr int kDx[4] = {-1, 1, 0, 0}, kDy[4] = {0, 0, -1, 1};
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      if (!domain.at<uint8_t>(y, x)) continue;
      for (int k = 0; k < 4; ++k) {
        const int ny = y + kDy[k], nx = x + kDx[k];
        if (linked(y, x, ny, nx) && anchor.at<uint8_t>(ny, nx) && !domain.at<uint8_t>(ny, nx)) {
          reached.at<uint8_t>(y, x) = 255;
          queue.emplace_back(x, y);
          break;
        }
      }
    }
  }
  while (!queue.empty()) {
    const cv::Point p = queue.front();
    queue.pop_front();
    for (int k = 0; k < 4; ++k) {
      const int ny = p.y + kDy[k], nx = p.x + kDx[k];
      if (!linked(p.y, p.x, ny, nx) || !domain.at<uint8_t>(ny, nx) || reached.at<uint8_t>(ny, nx)) continue;
      reached.at<uint8_t>(ny, nx) = 255;
      queue.emplace_back(nx, ny);
    }
  }
  cv::Mat out = (domain != 0) & (reached == 0);
  return out;
}

double AbsQuantile(const cv::Mat& values, const cv::Mat& where, double quantile, double floor) {
  std::vector<float> magnitudes;
  for (int y = 0; y < values.rows; ++y) {
    for (int x = 0; x < values.cols; ++x) {
      if (where.at<uint8_t>(y, x) != 0) magnitudes.push_back(std::abs(values.at<float>(y, x)));
    }
  }
  if (magnitudes.empty()) return floor;
  const auto k =
      static_cast<size_t>(std::clamp(quantile, 0.0, 1.0) * static_cast<double>(magnitudes.size() - 1));
  std::nth_element(magnitudes.begin(), magnitudes.begin() + static_cast<std::ptrdiff_t>(k), magnitudes.end());
  return std::max(floor, static_cast<double>(magnitudes[k]));
}

// Hole cells whose nearest known cells to the left and to the right in the same row both lack a return
// (CV_8U 255). A scan's rows are elevations: the sky over a lamp post, or the band beyond the far end of the
// ground, runs along the rows, so a cell between two no-return cells of its row has none either, whatever a
// patch copied from elsewhere says. Only no-return regions that reach the image's border count: dropouts and
// occlusion shadows inside a surface are enclosed by returns, and the surface continues behind the object.
cv::Mat NoReturnOnBothSides(const cv::Mat& hole, const cv::Mat& known_valid) {
  // The known cells without a return that are connected to the image's border (sky, beyond range).
  const cv::Mat no_return = (known_valid == 0) & (hole == 0);
  cv::Mat component;
  const int components = cv::connectedComponents(no_return, component, 8, CV_32S);
  std::vector<uint8_t> open(static_cast<size_t>(components), 0);
  for (int y = 0; y < hole.rows; ++y) {
    const int32_t* row = component.ptr<int32_t>(y);
    const bool edge_row = y == 0 || y == hole.rows - 1;
    for (int x = 0; x < hole.cols; ++x)
      if (row[x] > 0 && (edge_row || x == 0 || x == hole.cols - 1)) open[static_cast<size_t>(row[x])] = 1;
  }
  auto open_sky = [&](int y, int x) { return open[static_cast<size_t>(component.at<int32_t>(y, x))] != 0; };
  cv::Mat between = cv::Mat::zeros(hole.size(), CV_8U);
  for (int y = 0; y < hole.rows; ++y) {
    const uint8_t* in_hole = hole.ptr<uint8_t>(y);
    for (int x = 0; x < hole.cols;) {
      if (!in_hole[x]) {
        ++x;
        continue;
      }
      int end = x;
      while (end < hole.cols && in_hole[end]) ++end;  // the run [x, end) of hole cells
      if (x > 0 && end < hole.cols && open_sky(y, x - 1) && open_sky(y, end))
        between.row(y).colRange(x, end).setTo(255);
      x = end;
    }
  }
  return between;
}

// Cuts at the seams between two copies: an edge of the hole whose two cells were not copied from two
// neighbouring cells (or a known cell next to a copied one) is cut where the cells they show lie at depths more
// than `ratio` apart, as a depth jump of the scan itself would be. Shifted copies of a wall's top edge that land
// a row apart otherwise leave a gap in the copied jump, through which the Poisson step joins the wall to the
// facade behind it.
void SeamCuts(const cv::Mat& range, const cv::Mat& hole, const cv::Mat& source, double ratio,
              EdgeMasks* cuts) {
  if (ratio <= 0) return;
  auto shown = [&](int y, int x) {  // the cell a cell shows: itself when known, its source when copied
    return hole.at<uint8_t>(y, x) ? source.at<cv::Vec2i>(y, x) : cv::Vec2i(y, x);
  };
  auto seam_jump = [&](int y, int x, int ny, int nx, cv::Vec2i step) {
    const cv::Vec2i a = shown(y, x), b = shown(ny, nx);
    if (a[0] < 0 || b[0] < 0 || b == a + step) return false;  // one copy: its own edge decides
    const float ra = range.at<float>(a[0], a[1]), rb = range.at<float>(b[0], b[1]);
    return ra > 0 && rb > 0 && std::abs(ra - rb) > ratio * std::min(ra, rb);
  };
  for (int y = 0; y < hole.rows; ++y) {
    for (int x = 0; x < hole.cols; ++x) {
      if (x + 1 < hole.cols && (hole.at<uint8_t>(y, x) || hole.at<uint8_t>(y, x + 1)) &&
          seam_jump(y, x, y, x + 1, {0, 1}))
        cuts->right.at<uint8_t>(y, x) = 255;
      if (y + 1 < hole.rows && (hole.at<uint8_t>(y, x) || hole.at<uint8_t>(y + 1, x)) &&
          seam_jump(y, x, y + 1, x, {1, 0}))
        cuts->down.at<uint8_t>(y, x) = 255;
    }
  }
}

}  // namespace lidarshop::fill_internal
