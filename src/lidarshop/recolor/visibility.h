// Internal to the recolor module: which valid cells of a scan a camera (any model, geometry/camera_model.h)
// sees, by the occlusion test of recolor/recolor.h (scan mesh + silhouette skirts, z-buffer or segments).
// Shared by RecolorScan (one photo) and RecolorFromPhotos (every photo of a station).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera_model.h"
#include "lidarshop/geometry/mesh.h"
#include "lidarshop/raycast/raycast.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/view_cull.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop::recolor_internal {

// The scan mesh and its silhouette skirts, world frame. Z-buffer visibility rasterizes them into each
// camera's buffer (recolor/distance_raster.h); segment visibility casts into `segments`, an Embree scene of
// both (mesh geometry 0, skirts 1), built only for that method.
// `mesh_blocks`, `skirt_blocks` and `cells` (recolor/view_cull.h) let each camera skip the triangles and the
// cells its view cannot reach; built once, used by every photo.
struct OcclusionScene {
  TriangleMesh mesh;
  TriangleMesh skirts;
  std::unique_ptr<RaycastScene> segments;
  std::vector<Eigen::AlignedBox3f> mesh_blocks, skirt_blocks;
  CellBoxes cells;
};
OcclusionScene BuildOcclusionScene(const Scan& scan, const RecolorOptions& options);

struct SeenCell {
  int64_t cell = 0;       // row * cols + col
  Eigen::Vector2d pixel;  // where the cell's point projects (continuous pixels)
  double distance_m = 0;  // from the camera centre
  // The photo pixels sampled for its colour must show a surface within this of distance_m (z-buffer
  // visibility: no blend across a depth edge); infinite with segment visibility.
  double agree_m = std::numeric_limits<double>::infinity();
};

struct Visibility {
  std::vector<SeenCell> seen;  // in row-major cell order (empty when asked for `row_seen`)
  // With VisibleCells(..., by_row = true): the seen cells row by row instead (rows x their cells), not joined
  // into one list (a 10-megapoint station's photo sees ~2 million cells: 100 MB not copied).
  std::vector<std::vector<SeenCell>> row_seen;
  std::vector<int64_t> uncertain;  // cells by an occluding edge (RecolorOptions::edge_guard): not coloured
  int64_t returns = 0;             // valid cells
  int64_t outside_image = 0;       // behind the camera or projected outside the image
  int64_t hidden = 0;              // inside the image, occluded
  double edge_margin_px = 0;       // the edge guard's margin, photo pixels (0 without it)
  // Z-buffer visibility: the camera's distances (metres, per z-buffer pixel) and z-buffer pixels per photo
  // pixel; empty with segment visibility.
  cv::Mat distance_buffer;
  Eigen::Vector2d buffer_per_photo_px = Eigen::Vector2d::Ones();
  double zbuffer_seconds = 0;  // wall clock of the z-buffer (rasterization and erosion); 0 for segments
};

Visibility VisibleCells(const Scan& scan, const OcclusionScene& scene, const Camera& camera,
                        const RecolorOptions& options, bool by_row = false);

}  // namespace lidarshop::recolor_internal
