// User strokes for segmentation: from a painted PNG or from JSON polylines, into a stroke label image
// (CV_8U rows x cols, image orientation, values kStrokeNone / kStrokeObject / kStrokeBackground of
// segment.h).
//
// PNG (any size-matched 8-bit RGB or RGBA image, row 0 = top of the scan image): a cell is an OBJECT stroke
// when it is saturated green (G >= 160, R <= 96, B <= 96) and a BACKGROUND stroke when saturated red
// (R >= 160, G <= 96, B <= 96); everything else — black, transparent (alpha < 128), or the scan's own picture
// — is no stroke. Paint on a blank layer when the scan's picture itself has saturated greens or reds.
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

#include <string>

#include <opencv2/core.hpp>

namespace lidarshop {

// Classifies a painted RGB/RGBA CV_8U image (see above). Throws InputError naming `what` on a wrong type.
cv::Mat StrokesFromImage(const cv::Mat& painted, const std::string& what = "strokes");

// Parses the JSON schema above for a rows x cols image. Throws InputError naming `what`, the stroke index and
// the field on malformed input.
cv::Mat StrokesFromJson(const std::string& json_text, int rows, int cols,
                        const std::string& what = "strokes");

// Reads a .png (or other image) or .json stroke file; the result must be rows x cols (InputError otherwise).
cv::Mat ReadStrokes(const std::string& path, int rows, int cols);

// Paints strokes as a PNG-ready RGB image (object green, background red, rest black) — the inverse of
// StrokesFromImage.
cv::Mat StrokesToImage(const cv::Mat& strokes);

}  // namespace lidarshop
