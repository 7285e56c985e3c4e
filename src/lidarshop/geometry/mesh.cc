#include "lidarshop/geometry/mesh.h"

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {

Eigen::AlignedBox3f Bounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3f box;
  for (const auto& vertex : mesh.vertices) box.extend(vertex);
  return box;
}

Eigen::AlignedBox3f Bounds(const PointCloud& cloud) {
  Eigen::AlignedBox3f box;
  for (const auto& point : cloud.points) box.extend(point);
  return box;
}

void ValidateMesh(const TriangleMesh& mesh, const std::string& what) {
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      const int index = mesh.triangles[f][corner];
      if (index < 0 || index >= num_vertices) {
        ThrowInputError(what, fmt::format("triangle {}", f), "vertex index",
                        fmt::format("{} is outside [0, {})", index, num_vertices));
      }
    }
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!mesh.vertices[v].allFinite()) {
      ThrowInputError(what, fmt::format("vertex {}", v), "position", "not a finite number");
    }
  }
  auto check_size = [&](size_t size, size_t expected, const char* name) {
    if (size != 0 && size != expected) {
      ThrowInputError(what, "", name, fmt::format("has {} entries, expected {}", size, expected));
    }
  };
  check_size(mesh.vertex_normals.size(), mesh.vertices.size(), "vertex_normals");
  check_size(mesh.vertex_colors.size(), mesh.vertices.size(), "vertex_colors");
  check_size(mesh.triangle_colors.size(), mesh.triangles.size(), "triangle_colors");
  check_size(mesh.triangle_texcoords.size(), mesh.triangles.size(), "triangle_texcoords");
  const int num_texcoords = static_cast<int>(mesh.texcoords.size());
  for (size_t f = 0; f < mesh.triangle_texcoords.size(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      const int index = mesh.triangle_texcoords[f][corner];
      if (index < 0 || index >= num_texcoords) {
        ThrowInputError(what, fmt::format("triangle {}", f), "texcoord index",
                        fmt::format("{} is outside [0, {})", index, num_texcoords));
      }
    }
  }
}

double SurfaceArea(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& triangle : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[triangle[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[triangle[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[triangle[2]].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

std::vector<Eigen::Vector3f> ComputeVertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> normals(mesh.vertices.size(), Eigen::Vector3f::Zero());
  for (const auto& triangle : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[triangle[0]];
    const Eigen::Vector3f area_normal =
        (mesh.vertices[triangle[1]] - a).cross(mesh.vertices[triangle[2]] - a);
    for (int corner = 0; corner < 3; ++corner) normals[triangle[corner]] += area_normal;
  }
  for (auto& normal : normals) {
    const float norm = normal.norm();
    normal = norm > 0 ? Eigen::Vector3f(normal / norm) : Eigen::Vector3f::UnitZ();
  }
  return normals;
}

void AppendMesh(const TriangleMesh& other, TriangleMesh* mesh) {
  const Rgb8 grey(160, 160, 160);
  const int vertex_offset = static_cast<int>(mesh->vertices.size());
  const size_t old_vertices = mesh->vertices.size();
  const size_t old_triangles = mesh->triangles.size();
  const bool had_triangle_colors = !mesh->triangle_colors.empty() || old_triangles == 0;
  const bool had_vertex_colors = !mesh->vertex_colors.empty() || old_vertices == 0;

  mesh->vertices.insert(mesh->vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& triangle : other.triangles) {
    mesh->triangles.push_back(triangle + Eigen::Vector3i::Constant(vertex_offset));
  }
  // Colours: keep them when either side has them, padding the other with grey.
  if (!other.triangle_colors.empty() || (had_triangle_colors && !mesh->triangle_colors.empty())) {
    if (mesh->triangle_colors.size() < old_triangles) mesh->triangle_colors.resize(old_triangles, grey);
    if (!other.triangle_colors.empty()) {
      mesh->triangle_colors.insert(mesh->triangle_colors.end(), other.triangle_colors.begin(),
                                   other.triangle_colors.end());
    } else {
      mesh->triangle_colors.resize(mesh->triangles.size(), grey);
    }
  }
  if (!other.vertex_colors.empty() || (had_vertex_colors && !mesh->vertex_colors.empty())) {
    if (mesh->vertex_colors.size() < old_vertices) mesh->vertex_colors.resize(old_vertices, grey);
    if (!other.vertex_colors.empty()) {
      mesh->vertex_colors.insert(mesh->vertex_colors.end(), other.vertex_colors.begin(),
                                 other.vertex_colors.end());
    } else {
      mesh->vertex_colors.resize(mesh->vertices.size(), grey);
    }
  }
  // Normals survive only when both sides have them; textures cannot be merged here.
  if (!mesh->vertex_normals.empty() && other.vertex_normals.size() == other.vertices.size() &&
      mesh->vertex_normals.size() == old_vertices) {
    mesh->vertex_normals.insert(mesh->vertex_normals.end(), other.vertex_normals.begin(),
                                other.vertex_normals.end());
  } else {
    mesh->vertex_normals.clear();
  }
  mesh->texcoords.clear();
  mesh->triangle_texcoords.clear();
  mesh->texture.release();
}

}  // namespace lidarshop
