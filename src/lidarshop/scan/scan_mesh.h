// A triangle mesh of an organized scan: adjacent valid cells are joined (two triangles per 2 x 2
// block of cells), and edges across depth discontinuities are dropped, so that separate objects do
// not get joined by long "skirts".
//
// An edge between neighbouring cells a and b is kept when |r_a - r_b| <= max_range_jump_ratio * min(r_a, r_b)
// (ranges in metres) and, when max_edge_m > 0, |p_a - p_b| <= max_edge_m. Triangles face the scanner (counter-clockwise as seen from the scanner origin).
#pragma once

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct ScanMeshOptions {
  // Largest relative range difference of a kept edge (a fraction of the nearer range). 0.1 keeps the ground
  // down to about 6 degrees of grazing incidence at 0.1-degree steps and cuts the edge of an object 10 % in
  // front of its background.
  double max_range_jump_ratio = 0.1;
  // Longest kept edge between the two cells' points, metres (0 = no limit): cuts grazing surfaces and far
  // returns where neighbouring rays are far apart, which the relative jump alone keeps.
  double max_edge_m = 0.0;
  bool world_frame = false;  // vertices in the world frame (world_from_scanner) instead of the scanner frame
  void Check() const;        // throws OptionsError
};
template <>
const StructInfo& InfoOf<ScanMeshOptions>();

// #V = number of cells used by a kept triangle; vertex colours from scan.color (when present), vertex normals
// from scan.normal (when present).
TriangleMesh ScanToMesh(const Scan& scan, const ScanMeshOptions& options = {});

}  // namespace lidarshop
