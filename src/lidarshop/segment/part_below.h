// Internal to whole_object.cc: the growth of a closed part, which the parts across a depth step and the part
// an object rests on share, and the part in front of the object and below it that the object rests on
// (WholeObjectOptions::join_rests_on): the lower crate of a stack stroked on the box on top.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop::whole_object_internal {

inline constexpr uint8_t kInPart = 1, kRejected = 2;  // marks of the parts' `visited` map
inline constexpr int kPartDr[4] = {-1, 1, 0, 0}, kPartDc[4] = {0, 0, -1, 1};

// Grows `part` (holding its seed, marked kInPart in `visited`) over the 4-neighbours q of its cells p that are
// valid, not in `grown`, within jump_at(p) of p's range (else a step) and not `stops(p, q)` (what it stands
// on). It is open, and growth ends, when it reaches the region's edge, a cell rejected before or one that
// `enter(grown, q)` refuses (joined in depth to something it may not take: part of something larger), or holds
// more than max_cells cells. Returns true when closed. Its cells stay marked kInPart.
template <typename JumpAt, typename Enter, typename Stops>
bool GrowClosedPart(const Scan& scan, const cv::Mat& grown, const cv::Rect& region, size_t max_cells,
                    const JumpAt& jump_at, const Enter& enter, const Stops& stops, cv::Mat& visited,
                    std::vector<cv::Point>& part) {
  bool open = false;
  for (size_t i = 0; i < part.size() && !open; ++i) {
    const cv::Point p = part[i];
    for (int j = 0; j < 4 && !open; ++j) {
      const cv::Point q(p.x + kPartDc[j], p.y + kPartDr[j]);
      if (!region.contains(q)) {
        open = true;  // it runs on beyond the region
        continue;
      }
      if (visited.at<uint8_t>(q) == kInPart || !scan.valid.at<uint8_t>(q) || grown.at<uint8_t>(q)) continue;
      if (std::abs(scan.range.at<float>(q) - scan.range.at<float>(p)) > jump_at(p)) continue;  // a step
      if (stops(p, q)) continue;
      if (visited.at<uint8_t>(q) == kRejected || !enter(grown, q)) {
        open = true;
        continue;
      }
      visited.at<uint8_t>(q) = kInPart;
      part.push_back(q);
      open = part.size() > max_cells;
    }
  }
  return !open;
}

// From each object cell of `grown` in `region`, the cell below it in the grid, when nearer to the scanner or
// at about its range (the front face of a lower crate, or the top face it shows at grazing incidence), seeds a
// part: the cells joined to it in depth (|range step| <= jump_at), orientation aside (the crate's top and front
// faces meet at a right angle), that `enter(grown, q)` allows and `support(q)` does not hold (the ground it
// stands on). It is one the object rests on when it is closed (it meets nothing in depth that it may not take:
// a barrier, a part turned down, the region's edge), has at most max_cells cells, lies below the object's top,
// and its highest point is no higher than tolerance_m above the object's lowest points where they meet: the
// object stands on it. (A crate before a post's foot hides the post's foot, and the post's lowest visible
// points lie below the crate's top edge, on the ray that grazes it.) z is up in the scan's frame. Returns the
// cells of the first such part found (empty: none).
template <typename JumpAt, typename Enter, typename Support>
std::vector<cv::Point> PartItRestsOn(const Scan& scan, const cv::Mat& grown, const cv::Rect& region,
                                     size_t max_cells, double tolerance_m, const JumpAt& jump_at,
                                     const Enter& enter, const Support& support) {
  const int object_top = cv::boundingRect(grown).y;
  cv::Mat visited = cv::Mat::zeros(grown.size(), CV_8U);
  const auto stands_on = [&](const cv::Point&, const cv::Point& q) { return support(q); };
  for (int r = region.y; r + 1 < region.y + region.height; ++r) {
    for (int c = region.x; c < region.x + region.width; ++c) {
      const cv::Point a(c, r), seed(c, r + 1);
      if (!grown.at<uint8_t>(a) || !scan.valid.at<uint8_t>(a) || visited.at<uint8_t>(seed)) continue;
      if (!enter(grown, seed) || support(seed)) continue;
      if (scan.range.at<float>(seed) > scan.range.at<float>(a) + jump_at(a)) continue;  // behind: not below
      std::vector<cv::Point> part = {seed};
      visited.at<uint8_t>(seed) = kInPart;
      const bool closed =
          GrowClosedPart(scan, grown, region, max_cells, jump_at, enter, stands_on, visited, part);
      if (closed && cv::boundingRect(part).y > object_top) {
        // Its highest point, and the object's lowest points where they meet in the grid (object cells with a
        // part cell below them).
        float part_top = -std::numeric_limits<float>::infinity();
        float contact_low = std::numeric_limits<float>::infinity();
        for (const cv::Point& p : part) {
          part_top = std::max(part_top, scan.point.at<cv::Vec3f>(p)[2]);
          const cv::Point above(p.x, p.y - 1);
          if (above.y >= 0 && grown.at<uint8_t>(above) && scan.valid.at<uint8_t>(above))
            contact_low = std::min(contact_low, scan.point.at<cv::Vec3f>(above)[2]);
        }
        if (contact_low + tolerance_m >= part_top) return part;
      }
      for (const cv::Point& p : part) visited.at<uint8_t>(p) = kRejected;
    }
  }
  return {};
}

}  // namespace lidarshop::whole_object_internal
