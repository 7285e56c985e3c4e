// Correspondence files (docs/recolor.md): {"pairs": [...]} where every pair is one of
//   {"pixel": [u, v], "point": [x, y, z]}  photo pixel <-> world point (resection, recolour)
//   {"pixel": [u, v], "cell": [row, col]}  photo pixel <-> a scan cell (image orientation; its world point)
//   {"source": [x, y, z], "target": [x, y, z]}  landmark in two frames (align: rigid / similarity)
//   {"pixel_a": [u, v], "pixel_b": [u, v]}  the same point in two photos (align: homography / fundamental)
// Pixels are continuous coordinates: x right, y down, (0, 0) the top-left corner of the photo, (0.5, 0.5) the
// centre of its first pixel; points in the world frame, metres. Optional: "image_size_px": [width, height].
// One file holds one kind of pair.
#pragma once

#include <string>
#include <vector>

#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class PairKind { kPixelPoint, kLandmark, kPixelPixel };
template <>
const EnumInfo& EnumInfoOf<PairKind>();

struct Correspondences {
  PairKind kind = PairKind::kPixelPoint;
  std::vector<PixelPointPair> pixel_point;
  std::vector<PointPair> landmarks;
  std::vector<PixelPair> pixel_pixel;
  int width_px = 0, height_px = 0;  // "image_size_px" when given, else 0
  size_t size() const { return pixel_point.size() + landmarks.size() + pixel_pixel.size(); }
};

// Throws InputError naming `what`, the pair and the field (missing keys, wrong types, NaN, a cell outside
// `scan` or without a return, "cell" without a scan, kinds mixed in one file).
Correspondences ParseCorrespondences(const std::string& json_text, const std::string& what,
                                     const Scan* scan = nullptr);
Correspondences ReadCorrespondences(const std::string& path, const Scan* scan = nullptr);

// WorldPointOfCell (scan/scan.h), checked: the cell (row, col), image orientation. Throws InputError naming `what`,
// `place` and the field "cell" for a cell outside the scan or without a return.
Eigen::Vector3d WorldPointOfCell(const Scan& scan, int row, int col, const std::string& what,
                                 const std::string& place);

// The JSON text of pixel <-> point pairs (what `resection` reads back).
std::string PixelPointPairsToJson(const std::vector<PixelPointPair>& pairs, int width_px = 0,
                                  int height_px = 0);

}  // namespace lidarshop
