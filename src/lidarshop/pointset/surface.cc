#include "lidarshop/pointset/surface.h"

// Poisson reconstruction solves its linear system with Eigen (CGAL's Eigen3_support sets the same macro).
#define CGAL_EIGEN3_ENABLED 1

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/Scale_space_reconstruction_3/Advancing_front_mesher.h>
#include <CGAL/Scale_space_reconstruction_3/Jet_smoother.h>
#include <CGAL/Scale_space_surface_reconstruction_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/compute_average_spacing.h>
#include <CGAL/poisson_surface_reconstruction.h>
#include <CGAL/property_map.h>
#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
using PointWithNormal = std::pair<Point, Vector>;

Point ToCgal(const Eigen::Vector3f& p) { return Point(p.x(), p.y(), p.z()); }

TriangleMesh PoissonSurface(const PointCloud& cloud, const SurfaceOptions& options) {
  std::vector<Eigen::Vector3f> normals = cloud.normals;
  if (normals.empty()) {
    NormalOptions normal_options;
    normal_options.neighbors = options.normal_neighbors;
    normal_options.viewpoint = options.viewpoint;
    normals = EstimateNormals(cloud, normal_options).normals;
  }
  std::vector<PointWithNormal> input;
  input.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (normals[i].squaredNorm() == 0.0f) continue;  // too few neighbours for a normal
    input.emplace_back(ToCgal(cloud.points[i]), Vector(normals[i].x(), normals[i].y(), normals[i].z()));
  }
  if (input.size() < 10) throw InputError("surface: fewer than 10 points with a normal");
  const double spacing = CGAL::compute_average_spacing<CGAL::Sequential_tag>(
      input, 6, CGAL::parameters::point_map(CGAL::First_of_pair_property_map<PointWithNormal>()));
  CGAL::Surface_mesh<Point> mesh;
  const bool ok = CGAL::poisson_surface_reconstruction_delaunay(
      input.begin(), input.end(), CGAL::First_of_pair_property_map<PointWithNormal>(),
      CGAL::Second_of_pair_property_map<PointWithNormal>(), mesh, spacing, options.poisson_angle_deg,
      options.poisson_radius_spacings, options.poisson_distance_spacings);
  if (!ok || mesh.number_of_faces() == 0) {
    throw InputError("surface: the Poisson reconstruction failed (are the normals oriented consistently?)");
  }
  TriangleMesh result;
  std::vector<int> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), -1);
  for (const auto vertex : mesh.vertices()) {
    const Point& p = mesh.point(vertex);
    index[static_cast<size_t>(vertex)] = static_cast<int>(result.vertices.size());
    result.vertices.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                 static_cast<float>(p.z()));
  }
  for (const auto face : mesh.faces()) {
    Eigen::Vector3i triangle;
    int corner = 0;
    for (const auto vertex : CGAL::vertices_around_face(mesh.halfedge(face), mesh)) {
      if (corner < 3) triangle[corner] = index[static_cast<size_t>(vertex)];
      ++corner;
    }
    if (corner == 3) result.triangles.push_back(triangle);
  }
  return result;
}

TriangleMesh ScaleSpaceSurface(const PointCloud& cloud, const SurfaceOptions& options) {
  std::vector<Point> points;
  points.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud.points) points.push_back(ToCgal(p));
  CGAL::Scale_space_surface_reconstruction_3<Kernel> reconstruction(points.begin(), points.end());
  reconstruction.increase_scale(
      options.scale_space_iterations,
      CGAL::Scale_space_reconstruction_3::Jet_smoother<Kernel>(options.scale_space_neighbors));
  reconstruction.reconstruct_surface(
      CGAL::Scale_space_reconstruction_3::Advancing_front_mesher<Kernel>(options.max_edge_m));
  // The facets index the input order: they are put back on the original (unsmoothed) points.
  TriangleMesh result;
  result.vertices = cloud.points;
  for (auto facet = reconstruction.facets_begin(); facet != reconstruction.facets_end(); ++facet) {
    result.triangles.emplace_back(static_cast<int>((*facet)[0]), static_cast<int>((*facet)[1]),
                                  static_cast<int>((*facet)[2]));
  }
  if (result.triangles.empty()) throw InputError("surface: the scale-space reconstruction found no surface");
  // The advancing front orients the surface from the facet it starts at, which CGAL picks in an order that
  // depends on memory addresses: the same input came back with every triangle reversed from run to run (a
  // clean-clone CI failed on it). The triangles are turned to face away from the points' centroid (a
  // positive signed volume), the way a scan's surfaces face the scanner's side.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : result.vertices) centroid += p.cast<double>();
  centroid /= static_cast<double>(result.vertices.size());
  double volume = 0;
  for (const Eigen::Vector3i& t : result.triangles) {
    const Eigen::Vector3d a = result.vertices[t[0]].cast<double>() - centroid;
    const Eigen::Vector3d b = result.vertices[t[1]].cast<double>() - centroid;
    const Eigen::Vector3d c = result.vertices[t[2]].cast<double>() - centroid;
    volume += a.dot(b.cross(c));
  }
  if (volume < 0) {
    for (Eigen::Vector3i& t : result.triangles) std::swap(t[1], t[2]);
  }
  return result;
}

// Drops triangles with a corner farther than `distance_m` from every point of `cloud` (0 = none), and the
// vertices no triangle uses.
void KeepNear(const PointCloud& cloud, double distance_m, TriangleMesh* mesh) {
  std::vector<uint8_t> near(mesh->vertices.size(), 1);
  if (distance_m > 0) {
    const PointKdTree tree(cloud.points);
    for (size_t v = 0; v < near.size(); ++v) {
      near[v] = tree.NearestWithin(mesh->vertices[v], static_cast<float>(distance_m)).found();
    }
  }
  std::vector<int> index(mesh->vertices.size(), -1);
  TriangleMesh kept;
  for (const Eigen::Vector3i& triangle : mesh->triangles) {
    if (!near[triangle[0]] || !near[triangle[1]] || !near[triangle[2]]) continue;
    Eigen::Vector3i renumbered;
    for (int k = 0; k < 3; ++k) {
      int& slot = index[triangle[k]];
      if (slot < 0) {
        slot = static_cast<int>(kept.vertices.size());
        kept.vertices.push_back(mesh->vertices[triangle[k]]);
      }
      renumbered[k] = slot;
    }
    kept.triangles.push_back(renumbered);
  }
  *mesh = std::move(kept);
}

// CGAL's containers iterate in an order that depends on memory addresses: vertices sorted by position and
// triangles (each starting at its smallest index, orientation kept) sorted, so equal meshes are equal arrays.
void Canonicalize(TriangleMesh* mesh) {
  std::vector<int> order(mesh->vertices.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  const auto less = [&](int a, int b) {
    const Eigen::Vector3f& p = mesh->vertices[a];
    const Eigen::Vector3f& q = mesh->vertices[b];
    return std::tie(p.x(), p.y(), p.z(), a) < std::tie(q.x(), q.y(), q.z(), b);
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<int> new_index(order.size());
  std::vector<Eigen::Vector3f> vertices(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    new_index[order[i]] = static_cast<int>(i);
    vertices[i] = mesh->vertices[order[i]];
  }
  for (Eigen::Vector3i& t : mesh->triangles) {
    t = Eigen::Vector3i(new_index[t[0]], new_index[t[1]], new_index[t[2]]);
    while (t[0] > t[1] || t[0] > t[2]) t = Eigen::Vector3i(t[1], t[2], t[0]);
  }
  std::sort(mesh->triangles.begin(), mesh->triangles.end(),
            [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
              return std::tie(a[0], a[1], a[2]) < std::tie(b[0], b[1], b[2]);
            });
  mesh->vertices = std::move(vertices);
}

}  // namespace

void SurfaceOptions::Check() const { Validate(*this); }

TriangleMesh ReconstructSurface(const PointCloud& cloud, const SurfaceOptions& options) {
  options.Check();
  if (cloud.size() < 10)
    throw InputError(fmt::format("surface: {} points; at least 10 are needed", cloud.size()));
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite()) throw InputError("surface: the cloud has a non-finite point");
  }
  // A 3-D Delaunay triangulation (both methods build one) of points on one plane has no cells: CGAL crashes.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : cloud.points) mean += p.cast<double>();
  mean /= static_cast<double>(cloud.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3f& p : cloud.points) {
    const Eigen::Vector3d d = p.cast<double>() - mean;
    covariance += d * d.transpose();
  }
  const Eigen::Vector3d spread = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues();
  if (spread[0] <= 1e-12 * spread[2]) {
    throw InputError(
        "surface: the points lie on one plane (or a line); a surface reconstruction needs depth");
  }
  if (!cloud.normals.empty() && cloud.normals.size() != cloud.size()) {
    throw InputError("surface: the cloud's normals do not match its points");
  }
  // CGAL draws from its per-thread default generator (the mesher's initial points, the jet smoother's
  // samples): reseeded here, so the same input and seed give the same mesh on every call.
  CGAL::get_default_random() = CGAL::Random(static_cast<unsigned int>(options.seed));
  TriangleMesh mesh;
  try {
    mesh = options.method == SurfaceMethod::kPoisson ? PoissonSurface(cloud, options)
                                                     : ScaleSpaceSurface(cloud, options);
  } catch (const CGAL::Failure_exception& error) {
    throw InputError(fmt::format("surface: CGAL could not reconstruct these points ({}: {})", error.library(),
                                 error.message().empty() ? error.expression() : error.message()));
  }
  KeepNear(cloud, options.keep_within_m, &mesh);
  Canonicalize(&mesh);
  return mesh;
}

}  // namespace lidarshop
