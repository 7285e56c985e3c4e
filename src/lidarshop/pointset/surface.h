// Surfaces from points: a closed or bounded triangle mesh through a cloud, by CGAL (5.5, Debian libcgal-dev):
//   poisson      Kazhdan et al.'s Poisson reconstruction (CGAL::poisson_surface_reconstruction_delaunay):
//                the indicator function whose gradient matches the oriented normals, meshed by Delaunay
//                refinement. Needs normals (the cloud's own, or estimated and turned toward `viewpoint`);
//                watertight, so open scenes get a closing membrane: keep_within_m trims triangles farther
//                from every input point.
//   scale-space  Digne et al.'s scale-space reconstruction (CGAL::Scale_space_surface_reconstruction_3): the
//                points smoothed by jet fitting (a moving-least-squares polynomial surface per
//                neighbourhood), meshed by advancing front, then the triangles moved back onto the original
//                points. No normals needed; interpolating, so holes stay open.
// Chosen over Open3D / PCL, which have both too, because CGAL is header-only here (no 300-package PCL stack),
// sequential (same mesh on any thread count) and maintained for exactly this.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class SurfaceMethod { kPoisson, kScaleSpace };  // "poisson", "scale-space"
template <>
const EnumInfo& EnumInfoOf<SurfaceMethod>();

struct SurfaceOptions {
  SurfaceMethod method = SurfaceMethod::kPoisson;
  // Poisson: mesh quality (CGAL's surface mesher criteria, in units of the mean point spacing).
  double poisson_angle_deg = 20.0;           // smallest triangle angle, degrees, (0, 30]
  double poisson_radius_spacings = 30.0;     // largest Delaunay ball radius, mean spacings, > 0
  double poisson_distance_spacings = 0.375;  // largest distance to the implicit surface, mean spacings, > 0
  // Triangles with a corner farther than this from every input point are dropped (0 = keep all): trims the
  // membrane Poisson closes open scans with, metres, >= 0.
  double keep_within_m = 0.0;
  int normal_neighbors = 18;  // k for normals estimated when the cloud has none, >= 3
  // Scale-space: jet-smoothing iterations (more = smoother, fewer details) and neighbours per fit.
  int scale_space_iterations = 4;  // >= 0
  int scale_space_neighbors = 30;  // >= 6
  double max_edge_m = 0.0;         // advancing front: longest triangle edge, metres (0 = no limit), >= 0
  Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();  // estimated normals face it (the scanner)
  uint64_t seed = 1;   // CGAL's random choices (mesher seeds, smoothing samples); the low 32 bits are used
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<SurfaceOptions>();

// Throws InputError for fewer than 10 points, non-finite points or a failed reconstruction.
TriangleMesh ReconstructSurface(const PointCloud& cloud, const SurfaceOptions& options = {});

}  // namespace lidarshop
