// Silhouette alignment: the automatic resection's fallback (auto_resection.h, step 6) for a photo that shares
// no features with any rendering of the scan — pumpA's, taken from the far side of the objects, where the
// rendering shows the back of the scanner's surfaces with the colours of their front. What both sides still
// share: where things are (their outlines against what lies behind) and, in the scan's intensity, which
// surfaces are bright or dark. From a rough pose with known intrinsics:
//   1. Rotation search: the scan's intensity rendered from the rough pose on a canvas twice the photo's size,
//      the photo reduced to 192 px wide; every rotation of the camera about its centre (yaw and pitch within
//      ±8° in 0.5° steps, roll within ±3° in 1° steps) maps the photo into the canvas by a homography, and the
//      one with the highest mutual information (32 x 32 bins) between the photo and the rendering wins.
//   2. Local search: mutual information again, each of the six pose parameters moved in turn (pattern search,
//      step halved three times) with the scan rendered from each trial, at 192 and 384 px wide.
//   3. Silhouettes (iterated closest edges): the scan rendered from the estimate; its pixels on an occluding
//      contour (a nearer surface beside a farther one or nothing) whose scan cell is an occluding contour
//      seen from the scanner too (the near side of a range jump: a pole's or a tank's outline is one from
//      both sides, the edge of a shadow on the floor is not) are the model edges. Each is paired with the
//      nearest photo edge (Canny) of about the same orientation (within 34°; one distance transform per
//      orientation bin) within a radius (8, 4, 2 working px), moved onto that edge's line (point-to-line),
//      and the pose refined by Levenberg–Marquardt on the pairs; repeated until it moves less than 2 mm, at
//      384, 768 and 1536 px wide.
//   4. Accepted only when at least `min_edge_share` of the model edges lie within 1.5 px of a photo edge of
//      their orientation at 384 px wide and `min_fine_edge_share` at 768 px wide, the mutual information at
//      192 px wide is at least `min_mutual_information`, and at least `min_pairs` pairs agree. Calibrated on
//      pumpA alone (bench/results/recolor.md): its accepted cameras, 17–20 px from the hand-picked pairs,
//      have 0.35–0.38 and 0.249–0.262; a camera 104 px off (from a start 1 m and 5° off) 0.33 and 0.220,
//      refused ones 0.26–0.30 and 0.185. The mutual information does not tell them apart (0.15–0.19 both).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop {

struct SilhouetteAlignmentOptions {
  double min_edge_share = 0.3;           // model edges within 1.5 px of a photo edge, at 384 px wide
  double min_fine_edge_share = 0.24;     // the same at 768 px wide
  double min_mutual_information = 0.12;  // nats, 32 x 32 bins, at 192 px wide
  int min_pairs = 40;
};

struct SilhouetteAlignment {
  bool ok = false;
  PinholeCamera camera;               // photo pixels
  std::vector<PixelPointPair> pairs;  // the last round's (photo edge pixel, model edge point)
  int inliers = 0;                    // pairs within 2 px (at 1536 px wide) after the refinement
  double rms_px = 0;                  // their RMS, photo pixels (distance to the edge's line)
  double work_scale = 1;              // working pixels per photo pixel of the last stage
  double edge_share = 0;              // step 4, at 384 px wide
  double fine_edge_share = 0;         // step 4, at 768 px wide
  double mutual_information = 0;      // step 4
  std::string trace;                  // what each stage did
};

// `start`: the photo's intrinsics (its size) and the rough pose. `photo_grey`: CV_8U, the photo's size.
// Throws InputError (naming `what`) when the scan has neither intensity nor colour.
SilhouetteAlignment AlignSilhouettes(const Scan& scan, const cv::Mat& photo_grey, const PinholeCamera& start,
                                     const SilhouetteAlignmentOptions& options, const std::string& what);

}  // namespace lidarshop
