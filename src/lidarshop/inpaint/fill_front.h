// The fill front of the greedy loop with a cached priority per front pixel (internal to inpaint/).
//
// After a fill the front can change only within one pixel of the filled patch and the priorities only within
// the priority's influence radius, so Update() recomputes just those; Check() compares with a recomputation
// from scratch (InpaintOptions::check_bookkeeping).
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/inpaint/canvas.h"
#include "lidarshop/inpaint/priority.h"

namespace lidarshop {

// The fill front with cached priorities.
class Front {
 public:
  Front(const InpaintCanvas& canvas, PatchPriority& priority) : canvas_(canvas), priority_(priority) {
    flag_ = ComputeFillFront(canvas.known());
    value_ = cv::Mat::zeros(canvas.rows(), canvas.cols(), CV_64F);
    for (int r = 0; r < canvas.rows(); ++r) {
      for (int c = 0; c < canvas.cols(); ++c) {
        if (!flag_.at<uint8_t>(r, c)) continue;
        pixels_.push_back({r, c});
        value_.at<double>(r, c) = priority_.Priority(canvas, {r, c});
      }
    }
  }

  bool empty() const { return pixels_.empty(); }

  // Highest priority; ties: smallest (row, col).
  Pixel Best() const {
    Pixel best = pixels_.front();
    double best_value = value_.at<double>(best.row, best.col);
    for (const Pixel& p : pixels_) {
      const double v = value_.at<double>(p.row, p.col);
      if (v > best_value ||
          (v == best_value && canvas_.Index(p.row, p.col) < canvas_.Index(best.row, best.col))) {
        best = p;
        best_value = v;
      }
    }
    return best;
  }
  double Value(Pixel p) const { return value_.at<double>(p.row, p.col); }
  const std::vector<Pixel>& pixels() const { return pixels_; }

  // After Ψtarget was filled: the front can change only within one pixel of the patch; priorities within the
  // priority's influence radius.
  void Update(Pixel target) {
    const int R = canvas_.patch_radius();
    const cv::Rect image_rect(0, 0, canvas_.cols(), canvas_.rows());
    const cv::Rect front_box =
        cv::Rect(target.col - R - 1, target.row - R - 1, 2 * R + 3, 2 * R + 3) & image_rect;
    for (int r = front_box.y; r < front_box.y + front_box.height; ++r) {
      for (int c = front_box.x; c < front_box.x + front_box.width; ++c) {
        const uint8_t now = IsFront(r, c) ? 1 : 0;
        uint8_t& flag = flag_.at<uint8_t>(r, c);
        if (now && !flag) pixels_.push_back({r, c});
        flag = now;
      }
    }
    pixels_.erase(std::remove_if(pixels_.begin(), pixels_.end(),
                                 [&](const Pixel& p) { return !flag_.at<uint8_t>(p.row, p.col); }),
                  pixels_.end());
    const int reach = R + std::max(1, priority_.InfluenceRadius(canvas_));
    const cv::Rect dirty =
        cv::Rect(target.col - reach, target.row - reach, 2 * reach + 1, 2 * reach + 1) & image_rect;
    for (const Pixel& p : pixels_) {
      if (dirty.contains(cv::Point(p.col, p.row)))
        value_.at<double>(p.row, p.col) = priority_.Priority(canvas_, p);
    }
  }

  // Compares with a recomputation from scratch; throws std::logic_error naming the first stranded pixel.
  void Check() const {
    const cv::Mat fresh = ComputeFillFront(canvas_.known());
    int listed = 0;
    for (int r = 0; r < canvas_.rows(); ++r) {
      for (int c = 0; c < canvas_.cols(); ++c) {
        if (fresh.at<uint8_t>(r, c) != flag_.at<uint8_t>(r, c)) {
          throw std::logic_error(
              fmt::format("fill front: pixel (row {}, col {}) is {} but should be {}", r, c,
                          flag_.at<uint8_t>(r, c) ? "on the front (stranded)" : "off the front",
                          fresh.at<uint8_t>(r, c) ? "on it" : "off it"));
        }
        listed += fresh.at<uint8_t>(r, c);
      }
    }
    if (listed != static_cast<int>(pixels_.size())) {
      throw std::logic_error(
          fmt::format("fill front: {} pixels listed, {} on the front", pixels_.size(), listed));
    }
    for (const Pixel& p : pixels_) {
      const double cached = Value(p), now = priority_.Priority(canvas_, p);
      if (std::abs(cached - now) > 1e-9 * std::max(1.0, std::abs(now))) {
        throw std::logic_error(fmt::format("fill front: priority of (row {}, col {}) is stale: {} vs {}",
                                           p.row, p.col, cached, now));
      }
    }
  }

 private:
  bool IsFront(int r, int c) const {
    if (canvas_.IsKnown(r, c)) return false;
    return (r > 0 && canvas_.IsKnown(r - 1, c)) || (r + 1 < canvas_.rows() && canvas_.IsKnown(r + 1, c)) ||
           (c > 0 && canvas_.IsKnown(r, c - 1)) || (c + 1 < canvas_.cols() && canvas_.IsKnown(r, c + 1));
  }

  const InpaintCanvas& canvas_;
  PatchPriority& priority_;
  cv::Mat flag_, value_;
  std::vector<Pixel> pixels_;
};

}  // namespace lidarshop
