// The scan's own length scale at an object (segment.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

double RayAngleAt(const Scan& scan, const cv::Mat& cells) {
  LIDARSHOP_CHECK(cells.type() == CV_8U && cells.size() == cv::Size(scan.cols, scan.rows));
  // Angle between neighbouring rays, measured as the distance between the points of neighbouring cells over
  // their range: fitted, nominal or absent grids alike. Pairs across a depth edge (over 10 % apart in range)
  // or at grazing incidence are outliers; the median ignores them.
  std::vector<float> angles;
  for (int r = 0; r + 1 < scan.rows; ++r) {
    for (int c = 0; c + 1 < scan.cols; ++c) {
      if (!cells.at<uint8_t>(r, c) || !scan.valid.at<uint8_t>(r, c)) continue;
      const cv::Vec3f& p = scan.point.at<cv::Vec3f>(r, c);
      const float range = scan.range.at<float>(r, c);
      if (range <= 0) continue;
      for (const cv::Point& next : {cv::Point(c + 1, r), cv::Point(c, r + 1)}) {
        if (!scan.valid.at<uint8_t>(next)) continue;
        if (std::abs(scan.range.at<float>(next) - range) > 0.1f * range) continue;
        angles.push_back(static_cast<float>(cv::norm(scan.point.at<cv::Vec3f>(next) - p)) / range);
      }
    }
  }
  if (angles.empty()) return 0.0;
  std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  return angles[angles.size() / 2];
}

}  // namespace lidarshop
