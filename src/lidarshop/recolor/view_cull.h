// Internal to the recolor module: which parts of a scan a camera's image can reach at all, so that each photo
// of a station projects and rasterizes only those (a cube map's face sees about a sixth of the scan).
//
// A pinhole image's rays all lie inside a pyramid through the camera centre; its four side planes are
// bounded here from the unprojected rays of the image border (sampled densely, widened by a margin for a
// distortion that bends the border between samples). A point strictly outside one of them projects outside
// the image, and a triangle with its three corners outside the same plane meets no ray of the image, so
// skipping them changes no z-buffer pixel and no visibility (distance_raster_test, station_recolor_test
// compare culled with unculled). A pinhole whose border rays do not project back to their pixels (an
// undistortion that did not converge) gets no planes. Other models (fisheye, spherical, cylindrical) get no planes: nothing is
// culled.
//
// Boxes are kept per block of consecutive triangles of a mesh (a scan mesh's triangles run in row-major cell
// order, so a block is a short run of one row) and per segment of a scan row; a box outside one plane is
// skipped whole. All of it is plain arrays in, arrays out.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera_model.h"
#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop::recolor_internal {

struct ViewPlanes {
  int count = 0;  // 0: no bound (every point may be seen)
  // Camera frame, through the origin: a point p with normal[k] · p < 0 for some k is outside the image.
  Eigen::Vector3f normal[4];
  // The same planes in the world frame: normal_world[k] · (p − center_world) < 0 is outside.
  Eigen::Vector3d normal_world[4];
  Eigen::Vector3d center_world = Eigen::Vector3d::Zero();

  // Bit k set when `point_in_camera` is outside plane k.
  uint8_t Outcode(const Eigen::Vector3f& point_in_camera) const {
    uint8_t code = 0;
    for (int k = 0; k < count; ++k) code |= static_cast<uint8_t>(normal[k].dot(point_in_camera) < 0) << k;
    return code;
  }
  // True when every point of `box_world` is outside one plane (an empty box is outside).
  bool Outside(const Eigen::AlignedBox3f& box_world) const;
};

ViewPlanes ImageViewPlanes(const Camera& camera);

// Per block of `block_triangles` consecutive triangles of `mesh`, the box of their corners (the mesh's frame).
constexpr int kCullBlockTriangles = 256;
std::vector<Eigen::AlignedBox3f> TriangleBlockBoxes(const TriangleMesh& mesh,
                                                    int block_triangles = kCullBlockTriangles);

// Per segment of `segment_cols` cells of each scan row, the box of its valid points (world frame) and their
// count: boxes[row * segments + s], segments = ceil(cols / segment_cols).
struct CellBoxes {
  int segment_cols = 64;
  int segments = 0;
  std::vector<Eigen::AlignedBox3f> boxes;
  std::vector<int32_t> valid;
};
CellBoxes CellBoxesOf(const Scan& scan, int segment_cols = 64);

}  // namespace lidarshop::recolor_internal
