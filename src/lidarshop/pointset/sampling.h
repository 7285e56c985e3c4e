// Point sets from meshes, and local shape descriptors of point sets.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/pointset/kdtree.h"

namespace lidarshop {

// Points spread uniformly over a mesh's surface (area-weighted choice of triangle, uniform
// barycentric point), so that a model's points do not follow its triangulation (artist meshes put
// many small triangles on details).
struct SurfaceSamples {
  std::vector<Eigen::Vector3f> points;   // #S positions, the mesh's frame
  std::vector<Eigen::Vector3f> normals;  // #S unit geometric normals of the sampled triangles
  std::vector<int32_t> triangle_ids;     // #S index of the triangle each point lies on
};

// Bytes one sample takes in SurfaceSamples (position, normal, triangle id).
inline constexpr int64_t kSurfaceSampleBytes = 12 + 12 + 4;

// `count` samples; the same mesh, count and seed give the same samples on every machine (mt19937_64, own
// conversion to [0, 1)). Degenerate triangles (zero area) are never sampled. An empty mesh gives no samples.
// InputError when `count` samples do not fit the memory budget (util/memory_budget.h).
SurfaceSamples SampleSurface(const TriangleMesh& mesh, int64_t count, uint64_t seed);

// Surface variation (Pauly et al. 2002) of every point: λ0 / (λ0 + λ1 + λ2) of the covariance of
// its neighbours within `radius` (metres), λ0 the smallest eigenvalue. 0 on a plane, up to 1/3
// where the shape is isotropic (corners, edges, fine detail). Points with fewer than 3 neighbours
// get 1/3. `tree` must hold `points`.
std::vector<float> SurfaceVariation(const PointKdTree& tree, float radius);

}  // namespace lidarshop
