#include "lidarshop/fill/foreground.h"

#include <algorithm>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace lidarshop::fill_internal {
namespace {

constexpr float kFrontJumpM = 0.1f;  // metres: range noise and mixed cells stay below it
constexpr int kOpenCells = 8;        // cells without a return in a row that are open space behind a run

// The least range step between neighbouring cells of a row that is a silhouette (in metres, at range r): a
// wall seen at 84° from its normal steps r · 0.0016 · 10 per column of 0.09°, a person 3 m before a wall 35 m
// away steps 3 m.
float JumpM(float r, float ratio) { return kFrontJumpM + ratio * r; }

// What lies beyond one end of a run, seen from its end cell (range `r_end`) stepping by `step` from `x`.
enum class Beyond { kFarther, kOther };

Beyond Look(const float* range, const uint8_t* known, const uint8_t* hole, int cols, int x, int step,
            float r_end, float ratio) {
  int without_return = 0;  // cells without a return passed so far
  for (int k = x + step; k >= 0 && k < cols; k += step) {
    if (hole[k]) continue;  // beyond the hole, the far side's surface tells what continues behind it
    if (!known[k]) {
      // Nothing returned behind it over a stretch: sky, beyond range. A few cells without a return are a
      // dropout (a stereo cloud has them all over its table) and are passed like the hole.
      if (++without_return >= kOpenCells) return Beyond::kFarther;
      continue;
    }
    return range[k] > r_end + JumpM(r_end, ratio) ? Beyond::kFarther : Beyond::kOther;
  }
  if (without_return > 0) return Beyond::kOther;  // a dropout reaching the border: no evidence
  return Beyond::kOther;                          // the scan's border: no evidence
}

}  // namespace

cv::Mat FrontCells(const cv::Mat& range, const cv::Mat& known_valid, const cv::Mat& hole, double jump_ratio,
                   int reach_cells) {
  cv::Mat front(range.size(), CV_8U, cv::Scalar(0));
  if (!(jump_ratio > 0) || reach_cells <= 0) return front;
  const float ratio = static_cast<float>(jump_ratio);
  auto jump = [ratio](float a, float b) {
    const float nearer = std::min(a, b);
    return std::max(a, b) > nearer + JumpM(nearer, ratio);
  };
  for (int y = 0; y < range.rows; ++y) {
    const float* r = range.ptr<float>(y);
    const uint8_t* known = known_valid.ptr<uint8_t>(y);
    const uint8_t* in_hole = hole.ptr<uint8_t>(y);
    uint8_t* out = front.ptr<uint8_t>(y);
    int x = 0;
    while (x < range.cols) {
      if (!known[x]) {
        ++x;
        continue;
      }
      int end = x;  // the run [x, end] of known cells without a depth jump
      while (end + 1 < range.cols && known[end + 1] && !jump(r[end], r[end + 1])) ++end;
      const int length = end - x + 1;
      if (length <= reach_cells && x > 0 && end + 1 < range.cols &&
          Look(r, known, in_hole, range.cols, x, -1, r[x], ratio) == Beyond::kFarther &&
          Look(r, known, in_hole, range.cols, end, 1, r[end], ratio) == Beyond::kFarther) {
        std::fill(out + x, out + end + 1, uint8_t{255});
      }
      x = end + 1;
    }
  }
  return front;
}

cv::Mat FrontTouchingHole(const cv::Mat& front, const cv::Mat& range, const cv::Mat& hole,
                          const cv::Mat& known_valid, double max_range_m, int margin_cells) {
  cv::Mat ids;
  const int count = cv::connectedComponents(front, ids, 8, CV_32S);
  cv::Mat rim;
  cv::dilate(hole != 0, rim, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  std::vector<uint8_t> touching(static_cast<size_t>(count), 0);
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x)
      if (rim.at<uint8_t>(y, x) && ids.at<int32_t>(y, x) > 0) touching[ids.at<int32_t>(y, x)] = 1;
  std::vector<double> sum(static_cast<size_t>(count), 0.0);
  std::vector<int64_t> cells(static_cast<size_t>(count), 0);
  for (int y = 0; y < ids.rows; ++y) {
    for (int x = 0; x < ids.cols; ++x) {
      const int id = ids.at<int32_t>(y, x);
      if (id <= 0) continue;
      sum[static_cast<size_t>(id)] += range.at<float>(y, x);
      ++cells[static_cast<size_t>(id)];
    }
  }
  for (int id = 1; id < count; ++id)
    if (cells[static_cast<size_t>(id)] &&
        sum[static_cast<size_t>(id)] / cells[static_cast<size_t>(id)] > max_range_m)
      touching[static_cast<size_t>(id)] = 0;
  cv::Mat out(front.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x)
      if (touching[ids.at<int32_t>(y, x)] && ids.at<int32_t>(y, x) > 0) out.at<uint8_t>(y, x) = 255;
  if (margin_cells > 0 && cv::countNonZero(out) > 0) {
    const int size = 2 * margin_cells + 1;
    cv::dilate(out, out, cv::getStructuringElement(cv::MORPH_ELLIPSE, {size, size}));
  }
  out &= (known_valid != 0) & (hole == 0);
  return out;
}

}  // namespace lidarshop::fill_internal
