// Silhouette skirts: the geometry an occluder may have where the scan could not sample it, for visibility
// tests against the scan's grid mesh (recolor.h).
//
// The grid mesh (scan/scan_mesh.h) drops the edges across depth jumps, so every occluder's mesh stops at
// its last cell. Its true silhouette lies somewhere between that cell's ray and the next ray (the one that
// passed the occluder): up to one angular cell spacing beyond the mesh, i.e. spacing × the occluder's range in
// metres. Seen from a camera beside the scanner, a point just behind the occluder's edge looks through that
// gap. Nor does the scan know the occluder's faces that turn away from the scanner (its sides inside the
// scanner's shadow): a camera that looks past the edge sees them, and they hide what lies behind.
//
// For every 2 x 2 block of cells that the grid mesh does not fill completely (a depth jump, or a cell without
// a return), each depth layer of the block except the farthest (cells joined by the mesh's edge rule) gets
//   - a cap: the layer's own points, and at the block's other corners the layer's surface carried one cell
//     further along those corners' rays (range extrapolated linearly from the layer's cell and the one
//     before it, within the jump ratio, always in front of the farther cell's return). The union of caps
//     grows every occluder by exactly one cell, at its own range and slope: the largest silhouette consistent
//     with the scan, since the neighbouring ray returned from farther away.
//   - with `depth_m` > 0, walls: the cap's four sides swept `depth_m` back along their rays (never past a
//     farther cell's return): an occluder at least that deep behind its edge, which the scan's shadow hides.
// A block with cells without a return caps every layer (the silhouette against the sky).
// With `depth_per_width` > 0 a wall is no deeper than that many times the occluder's width where the scan saw
// it whole: the run of joined cells through the corner along its row, and along its column, that ends on both
// sides at a farther return or none (a silhouette, not another occluder in front); the narrower run counts. A
// post 8 cm wide is not 25 cm deep, and a 25 cm wall behind it hides a strip of the façade the camera sees.
// A run that ends at a nearer surface is a part of something larger: it keeps `depth_m`.
#pragma once

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop {

struct SilhouetteSkirtOptions {
  double max_range_jump_ratio = 0.1;  // the grid mesh's edge rule (scan/scan_mesh.h), fraction of range
  double depth_m = 0.0;               // walls swept this far back behind each cap, metres; 0 = caps only
  double depth_per_width = 0.0;       // walls at most this × the occluder's seen width (above); 0 = no limit
  bool world_frame = true;            // vertices in the world frame (world_from_scanner), else scanner frame
};

// Triangles of the caps and walls (no attributes). Cells whose direction is unknown (zero) make no skirt.
TriangleMesh SilhouetteSkirts(const Scan& scan, const SilhouetteSkirtOptions& options = {});

}  // namespace lidarshop
