// Triangle meshes and point clouds: the plain containers every module exchanges.
//
// Arrays follow libigl's habit of stating shapes: #V vertices, #F triangles, #P points. Units are metres
// unless a function says otherwise; the frame is whatever the owner says (`mesh_in_world`,
// `points_in_scanner`).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace lidarshop {

using Rgb8 = Eigen::Matrix<uint8_t, 3, 1>;

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;   // #V positions
  std::vector<Eigen::Vector3i> triangles;  // #F vertex indices, counter-clockwise seen from the front
  // Optional attributes: each is empty or has the size stated.
  std::vector<Eigen::Vector3f> vertex_normals;  // #V unit normals
  std::vector<Rgb8> vertex_colors;              // #V RGB
  std::vector<Rgb8> triangle_colors;            // #F RGB (e.g. an OBJ material's diffuse colour)
  std::vector<Eigen::Vector2f> texcoords;       // #T texture coordinates, (0,0) = bottom left of `texture`
  std::vector<Eigen::Vector3i> triangle_texcoords;  // #F indices into texcoords, one per corner
  cv::Mat texture;                                  // CV_8UC3 RGB image (empty = none)

  size_t num_vertices() const { return vertices.size(); }
  size_t num_triangles() const { return triangles.size(); }
  bool empty() const { return triangles.empty(); }
};

struct PointCloud {
  std::vector<Eigen::Vector3f> points;  // #P positions
  // Optional attributes: each is empty or has #P entries.
  std::vector<Eigen::Vector3f> normals;  // unit normals
  std::vector<Rgb8> colors;              // RGB
  std::vector<float> intensities;        // [0, 1]
  std::vector<int32_t> labels;           // object labels
  std::vector<uint8_t> synthesized;      // 1 = created by lidarshop (hole filling), 0 = measured

  size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
};

// Axis-aligned bounds of the vertices (an empty box for an empty mesh).
Eigen::AlignedBox3f Bounds(const TriangleMesh& mesh);
Eigen::AlignedBox3f Bounds(const PointCloud& cloud);

// Checks index ranges and attribute sizes; throws InputError naming `what` (e.g. the file) when broken.
void ValidateMesh(const TriangleMesh& mesh, const std::string& what);

// Total surface area in squared units.
double SurfaceArea(const TriangleMesh& mesh);

// Per-vertex normals as the area-weighted average of the incident faces' normals.
std::vector<Eigen::Vector3f> ComputeVertexNormals(const TriangleMesh& mesh);

// Appends `other` to `mesh` (indices shifted). Attributes present in only one side are dropped unless they
// can be filled (triangle_colors/vertex_colors get a neutral grey for the side that lacks them).
void AppendMesh(const TriangleMesh& other, TriangleMesh* mesh);

}  // namespace lidarshop
