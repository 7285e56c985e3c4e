// Internal to the recolor module: a camera's z-buffer over the occlusion scene (the scan mesh and its
// silhouette skirts), as the distance from the camera centre to the first surface along each pixel's ray.
//
// Two ways to the same buffer:
// - CastDistanceBuffer casts every pixel's ray into an Embree scene (the reference);
// - RasterDistanceBuffer tests each triangle only against the pixels its projection covers, with the same
//   exact ray–triangle test per pixel. A scan mesh has tens of millions of triangles of a pixel or two each,
//   so this skips building a BVH over them (most of the time of colouring a station from its photos) and
//   runs as one loop over triangles: the shape a GPU back end would take over. Triangles whose projection
//   cannot be bounded from their corners (a corner that does not project, a panorama's seam, wider than
//   RasterOptions::max_raster_px) go to a small Embree scene of their own, cast for every pixel.
// The nearest hit wins; equal distances go to the lower triangle index, so the buffer does not depend on the
// thread count.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera_model.h"
#include "lidarshop/geometry/mesh.h"
#include "lidarshop/raycast/raycast.h"

namespace lidarshop::recolor_internal {

struct DistanceBuffer {
  cv::Mat distance;     // CV_32F, metres from the camera centre; +inf: no surface, or a pixel without a ray
  cv::Mat back_facing;  // CV_8U, 255 where the first surface is a scan-mesh triangle seen from behind
  int64_t cast_triangles = 0;  // RasterDistanceBuffer: triangles left to the Embree scene
};

// Buffer size: the photo's size times `scale` (rounded, at least 1 x 1), pixel centres mapped back to photo
// pixels. Geometry 0 of `scene` is the scan mesh, geometry 1 the skirts (no surface of the scan: never back
// facing).
DistanceBuffer CastDistanceBuffer(const RaycastScene& scene, const Camera& camera, double scale);

struct RasterOptions {
  // Triangles whose corners' bounding box is wider or taller than this (buffer pixels) are cast, not
  // rasterized: a camera model other than an undistorted pinhole bends edges, and the box is padded only by
  // bend_margin × its size (a 96-pixel edge of a panorama bends by well under a pixel within 90°).
  int max_raster_px = 96;
  double bend_margin = 0.05;
  // Skip the triangles outside the image's view (recolor/view_cull.h: a pinhole's pyramid; a block of
  // triangles whose box lies outside it is skipped whole). The buffer is the same either way.
  bool cull_outside_view = true;
};

// The boxes of each mesh's blocks of triangles (recolor/view_cull.h TriangleBlockBoxes), computed once for
// all the photos of a station; null: computed here when the camera has view planes.
struct RasterBlockBoxes {
  const std::vector<Eigen::AlignedBox3f>* mesh = nullptr;
  const std::vector<Eigen::AlignedBox3f>* skirts = nullptr;
};

DistanceBuffer RasterDistanceBuffer(const TriangleMesh& mesh, const TriangleMesh& skirts,
                                    const Camera& camera, double scale, const RasterOptions& options = {},
                                    const RasterBlockBoxes& block_boxes = {});

}  // namespace lidarshop::recolor_internal
