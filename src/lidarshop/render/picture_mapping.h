// Painting on the picture `render` wrote: which cells of a scan the pixels of a picture show, so that strokes
// and masks drawn on any picture `render` draws of the scan (grid or sphere layout in square angular pixels at
// any width; top, front and side views) become cells of the scan's grid (docs/file-formats.md, "Picture
// layout file").
//
// `render` writes the mapping beside its picture as PICTURE.layout.json (LayoutFilePath):
//   {"format": "lidarshop picture layout", "version": 1,
//    "scan_rows": 1074, "scan_cols": 345,           the scan the picture shows (its grid, cells)
//    "view": "grid",                                grid | sphere | top | front | side
//    "image_width": 1336, "image_height": 1074,     the whole picture file (a legend may sit to the right)
//    "picture_width": 1276, "picture_height": 1074, the part showing the scan, from the top-left corner
//    "pixel_width": 0.0675, "pixel_height": 0.0675, "pixel_unit": "deg",
//    "azimuth_left_rad": ..., "elevation_top_rad": ...,            sphere only: the picture's left and top
//    "azimuth_step_rad": ..., "elevation_step_rad": ...,           edges and a pixel's size (scanner frame)
//    "point_size_px": 0,                            top / front / side only: the --point-size it was drawn with
//                                                   (0 = automatic),
//    "left_m": ..., "top_m": ...}                   and the world coordinates of the picture's left and top
//                                                   edges (top: x, y; front: x, z; side: y, z), metres
//
// Pixels to cells. grid: the picture is the grid resampled by nearest neighbour (render_layout.h,
// ResampleNearest), so a cell's pixels are those whose centre falls in it, or the pixel holding its centre
// when the picture is coarser than the grid (then one pixel speaks for several cells). sphere: a cell's pixel
// is where its ray (the point's own direction for a return, else the cell's grid direction) meets the
// spherical grid, widened to half a ray step on each side when pixels are finer than rays. A cell takes the
// most frequent non-zero value among its pixels (strokes: object or background; masks: set when any of its
// pixels is set), else 0. top / front / side: the file holds no pixel-to-cell table (it would be as large as
// the picture); the view is laid out again from the scan and the file's sizes (LayOutPicture is
// deterministic), each pixel showing the cell whose point won it (PictureLayout::source_cells). Only cells
// that show can be painted: a point hidden under another in that view is not reached.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "lidarshop/render/render_layout.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop {

struct PictureMapping {
  PictureView view = PictureView::kGrid;  // never kAuto
  int scan_rows = 0, scan_cols = 0;       // the scan's grid, cells
  cv::Size image_size;                    // the whole picture file, pixels
  cv::Size picture_size;                  // its part that shows the scan (top-left), pixels
  double pixel_width = 0, pixel_height = 0;
  std::string pixel_unit = "deg";
  // Sphere: the azimuth of the picture's left edge, the elevation of its top edge and a pixel's size across
  // and down, radians, scanner frame (azimuths left of the edge are taken one turn later).
  double azimuth_left_rad = 0, elevation_top_rad = 0, azimuth_step_rad = 0, elevation_step_rad = 0;
  // top / front / side: the --point-size the picture was drawn with (0 = automatic), and for each picture pixel
  // the cell it shows (PictureLayout::source_cells; not in the file: FindPictureMapping lays the view out again).
  int point_size_px = 0;
  cv::Mat source_cells;
  double left_m = 0, top_m = 0;  // top / front / side: PictureLayout::left_m, top_m (metres)
};

// True for the views whose pixels map onto cells (every view but kAuto).
bool HasCellMapping(PictureView view);

// The mapping of a laid-out picture of `scan`, drawn in the top-left of an image of `image_size` (the picture
// plus a legend; empty = the picture alone).
PictureMapping MappingOfLayout(const PictureLayout& layout, const Scan& scan, cv::Size image_size = {});

// The layout file (see the top) and back; ParsePictureMapping throws InputError naming `what` and the field.
// A top / front / side mapping read from a file has no source_cells yet (FindPictureMapping adds them).
nlohmann::ordered_json PictureMappingJson(const PictureMapping& mapping);
// `scan`: the scan laid out; `image_size`: the picture file (empty = the laid-out picture alone).
nlohmann::ordered_json LayoutFileJson(const PictureLayout& layout, const Scan& scan, cv::Size image_size);
PictureMapping ParsePictureMapping(const std::string& text, const std::string& what);

// PICTURE.layout.json: where `render` writes the layout of PICTURE.
std::string LayoutFilePath(const std::string& picture_path);

// The cells' values from a CV_8U picture of `mapping.image_size` (see the top for the rule): CV_8U
// scan_rows x scan_cols. Throws std::logic_error when the scan or the picture does not match the mapping.
cv::Mat CellsFromPicture(const Scan& scan, const PictureMapping& mapping, const cv::Mat& picture);

// How a picture painted for `scan` maps onto its cells, in this order: none (std::nullopt) when it has the
// grid's size (one pixel per cell); the layout file `layout_path` when given, else PICTURE.layout.json when
// it exists beside the picture, when it names this scan's grid and the picture's size; else render's default
// layout (LayOutPicture with default options) at the picture's width or height, when that gives the
// picture's size. Otherwise throws InputError naming the picture, the sizes it may have and how to get a
// picture to paint on (`what_scan` names the scan file in that sentence).
std::optional<PictureMapping> FindPictureMapping(const Scan& scan, const std::string& picture_path,
                                                 cv::Size picture_size, const std::string& layout_path,
                                                 const std::string& what_scan);

// A mask picture for `scan` (white = set, as ReadMask): of the scan's grid size, or any picture render wrote
// (FindPictureMapping) mapped onto the cells. CV_8U 255/0, scan rows x cols. InputError as ReadMask and
// FindPictureMapping.
cv::Mat ReadMaskForScan(const std::string& path, const Scan& scan, const std::string& layout_path,
                        const std::string& what_scan);

}  // namespace lidarshop
