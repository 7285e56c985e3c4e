// User strokes for segmentation: from a painted PNG or from JSON polylines, into a stroke label image
// (CV_8U rows x cols, image orientation, values kStrokeNone / kStrokeObject / kStrokeBackground below). Read
// here, beside the pictures they are painted on; segment/ cuts from the label image.
//
// PNG (any size-matched 8-bit RGB or RGBA image, row 0 = top of the scan image): a cell is an OBJECT stroke
// when it is saturated green (G >= 160, R <= 96, B <= 96) and a BACKGROUND stroke when saturated red
// (R >= 160, G <= 96, B <= 96); everything else — black, transparent (alpha < 128), or the scan's own picture
// — is no stroke. Paint on a blank layer when the scan's picture itself has saturated greens or reds.
//
// A stroke picture may also be painted on any picture `render` wrote of the scan (square angular pixels, any
// width; render/picture_mapping.h): its strokes are mapped onto the grid's cells (ReadStrokesForScan).
//
// JSON polylines in grid coordinates:
//   {"strokes": [
//      {"label": "object",     "width": 3, "points": [[col, row], [col, row], ...]},
//      {"label": "background", "points": [[120, 40], [180, 42]]}
//   ]}
// `label` is "object" (alias "foreground") or "background"; `points` holds one or more [col, row]
// pairs (numbers; col = x to the right, row = y down from the top row), joined by straight segments;
// `width` is the line thickness in cells (default 1, 1..255). Points must lie inside the image. Later
// strokes paint over earlier ones.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/render/picture_mapping.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop {

// Stroke label images: CV_8U rows x cols (image orientation), one of these values per cell.
constexpr uint8_t kStrokeNone = 0;
constexpr uint8_t kStrokeObject = 1;
constexpr uint8_t kStrokeBackground = 2;

// Classifies a painted RGB/RGBA CV_8U image (see above). Throws InputError naming `what` on a wrong type.
cv::Mat StrokesFromImage(const cv::Mat& painted, const std::string& what = "strokes");

// Parses the JSON schema above for a rows x cols image. Throws InputError naming `what`, the stroke index and
// the field on malformed input.
cv::Mat StrokesFromJson(const std::string& json_text, int rows, int cols,
                        const std::string& what = "strokes");

// Reads a .png (or other image) or .json stroke file; the result must be rows x cols (InputError otherwise).
cv::Mat ReadStrokes(const std::string& path, int rows, int cols);

// Strokes read for a scan: on its grid, and as painted.
struct PaintedStrokes {
  cv::Mat cells;  // stroke labels on the scan's grid, CV_8U rows x cols
  // The labels as painted in the picture's pixels (CV_8U, mapping->picture_size) when the strokes were painted
  // on a picture `render` wrote; empty for JSON strokes and stroke pictures of the grid's own size.
  cv::Mat picture;
  std::optional<PictureMapping> mapping;  // how that picture maps onto the cells
  // One line for stderr: where the strokes were painted and the cells they became ("strokes painted on a
  // 1276 x 1074 grid picture: 52 object and 940 background cells").
  std::string Describe() const;
};

// Reads a .json stroke file (grid coordinates) or a stroke picture of the grid's size or of any picture
// `render` wrote of the scan (FindPictureMapping: `layout_path` or PICTURE.layout.json beside it, else
// render's default layout at its width), mapped onto the cells (CellsFromPicture). Throws InputError naming
// the file, the sizes it may have and how to get a picture to paint on; `what_scan` names the scan.
PaintedStrokes ReadStrokesForScan(const std::string& path, const Scan& scan, const std::string& layout_path,
                                  const std::string& what_scan);

// Paints strokes as a PNG-ready RGB image (object green, background red, rest black) — the inverse of
// StrokesFromImage.
cv::Mat StrokesToImage(const cv::Mat& strokes);

}  // namespace lidarshop
