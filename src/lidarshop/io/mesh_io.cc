#include "lidarshop/io/mesh_io.h"

#include <filesystem>

#include <fmt/format.h>

#include "lidarshop/io/image_io.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/obj.h"
#include "lidarshop/io/ply.h"
#include "lidarshop/io/ply_fields.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using namespace io_internal;  // NOLINT: the PLY field helpers and TextureToRgb8

TriangleMesh MeshFromPly(const PlyData& ply, const std::string& path, std::vector<std::string>* warnings) {
  TriangleMesh mesh;
  const PlyElement& vertex = RequireElement(ply, "vertex", path);
  mesh.vertices = Vector3Property(vertex, "x", "y", "z", path, true);
  mesh.vertex_normals = Vector3Property(vertex, "nx", "ny", "nz", path, false);
  mesh.vertex_colors = ColorProperty(vertex);
  const PlyElement* face = ply.Find("face");
  if (face == nullptr || face->count == 0)
    ThrowInputError(path, "header", "element face", "missing: no triangles");
  const PlyProperty* indices = face->Find("vertex_indices");
  if (indices == nullptr) indices = face->Find("vertex_index");
  if (indices == nullptr || !indices->is_list) {
    ThrowInputError(path, "header", "face vertex_indices", "missing (expected a list property)");
  }
  const std::vector<Rgb8> face_colors = ColorProperty(*face);
  const PlyProperty* face_texcoord = face->Find("texcoord");
  // Per-vertex texture coordinates under their usual names.
  std::vector<Eigen::Vector2f> vertex_texcoords;
  for (auto [u, v] : {std::pair{"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}}) {
    const PlyProperty* pu = vertex.Find(u);
    const PlyProperty* pv = vertex.Find(v);
    if (pu != nullptr && pv != nullptr && !pu->is_list && !pv->is_list) {
      for (int64_t i = 0; i < vertex.count; ++i) vertex_texcoords.emplace_back(pu->values[i], pv->values[i]);
      break;
    }
  }
  for (int64_t f = 0; f < face->count; ++f) {
    const int64_t begin = indices->offsets[f], end = indices->offsets[f + 1];
    if (end - begin < 3) {
      ThrowInputError(path, fmt::format("face {}", f), "vertex_indices",
                      fmt::format("a face needs 3 vertices, found {}", end - begin));
    }
    for (int64_t i = begin + 1; i + 1 < end; ++i) {
      mesh.triangles.emplace_back(ToInt32(indices->values[begin]), ToInt32(indices->values[i]),
                                  ToInt32(indices->values[i + 1]));
      if (!face_colors.empty()) mesh.triangle_colors.push_back(face_colors[f]);
      if (face_texcoord != nullptr && face_texcoord->is_list &&
          face_texcoord->offsets[f + 1] - face_texcoord->offsets[f] == 2 * (end - begin)) {
        const int64_t t = face_texcoord->offsets[f];
        const int base = static_cast<int>(mesh.texcoords.size());
        for (int64_t corner : {int64_t{0}, i - begin, i + 1 - begin}) {
          mesh.texcoords.emplace_back(face_texcoord->values[t + 2 * corner],
                                      face_texcoord->values[t + 2 * corner + 1]);
        }
        mesh.triangle_texcoords.emplace_back(base, base + 1, base + 2);
      }
    }
  }
  if (mesh.triangle_texcoords.empty() && !vertex_texcoords.empty()) {
    mesh.texcoords = vertex_texcoords;
    mesh.triangle_texcoords = mesh.triangles;
  }
  if (mesh.triangle_texcoords.size() != mesh.triangles.size()) {
    mesh.texcoords.clear();
    mesh.triangle_texcoords.clear();
  }
  for (const std::string& comment : ply.comments) {
    if (comment.rfind("TextureFile ", 0) != 0 || mesh.triangle_texcoords.empty()) continue;
    const std::string name = comment.substr(12);
    try {
      mesh.texture = ReadImage((std::filesystem::path(path).parent_path() / name).string());
      mesh.texture = io_internal::TextureToRgb8(mesh.texture);
    } catch (const InputError& error) {
      warnings->push_back(fmt::format("{}: {} (the mesh is read without its texture)", path, error.what()));
    }
    break;
  }
  ValidateMesh(mesh, path);
  return mesh;
}

}  // namespace

MeshFile ReadMeshFile(const std::string& path) {
  const std::string extension = FileExtension(path);
  MeshFile file;
  file.path = path;
  if (extension == "obj") {
    file.mesh = ReadObj(path, &file.warnings);
  } else if (extension == "ply") {
    file.mesh = MeshFromPly(ReadPly(path), path, &file.warnings);
  } else {
    ThrowInputError(path, "", "",
                    fmt::format("unknown mesh format '.{}' (lidarshop reads .obj and .ply)", extension));
  }
  if (file.mesh.triangles.empty()) ThrowInputError(path, "", "", "the file holds no triangles");
  return file;
}

TriangleMesh ReadMesh(const std::string& path) { return ReadMeshFile(path).mesh; }

void WriteMesh(const std::string& path, const TriangleMesh& mesh, bool ascii) {
  if (FileExtension(path) != "ply") {
    ThrowInputError(path, "", "", "lidarshop writes meshes as .ply only");
  }
  ValidateMesh(mesh, "WriteMesh");
  PlyData ply;
  ply.format = ascii ? PlyData::Format::kAscii : PlyData::Format::kBinaryLittleEndian;
  ply.comments.push_back("written by lidarshop");
  PlyElement vertex{"vertex", static_cast<int64_t>(mesh.vertices.size()), {}};
  AddVector3Property(&vertex, mesh.vertices, "x", "y", "z");
  if (!mesh.vertex_normals.empty()) AddVector3Property(&vertex, mesh.vertex_normals, "nx", "ny", "nz");
  if (!mesh.vertex_colors.empty()) AddColorProperty(&vertex, mesh.vertex_colors);
  PlyElement face{"face", static_cast<int64_t>(mesh.triangles.size()), {}};
  PlyProperty indices;
  indices.name = "vertex_indices";
  indices.is_list = true;
  indices.type = PlyType::kInt32;
  indices.offsets.reserve(mesh.triangles.size() + 1);
  indices.values.reserve(3 * mesh.triangles.size());
  indices.offsets.push_back(0);
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    for (int corner = 0; corner < 3; ++corner) indices.values.push_back(triangle[corner]);
    indices.offsets.push_back(static_cast<int64_t>(indices.values.size()));
  }
  face.properties.push_back(std::move(indices));
  if (!mesh.triangle_colors.empty()) AddColorProperty(&face, mesh.triangle_colors);
  if (!mesh.texture.empty() && !mesh.triangle_texcoords.empty()) {
    // MeshLab's convention: a per-face list of u v pairs and the texture file named in a comment.
    PlyProperty texcoord;
    texcoord.name = "texcoord";
    texcoord.is_list = true;
    texcoord.type = PlyType::kFloat32;
    texcoord.offsets.push_back(0);
    for (const Eigen::Vector3i& corners : mesh.triangle_texcoords) {
      for (int corner = 0; corner < 3; ++corner) {
        texcoord.values.push_back(mesh.texcoords[corners[corner]].x());
        texcoord.values.push_back(mesh.texcoords[corners[corner]].y());
      }
      texcoord.offsets.push_back(static_cast<int64_t>(texcoord.values.size()));
    }
    face.properties.push_back(std::move(texcoord));
    const std::filesystem::path target(path);
    const std::string texture_name = target.stem().string() + "_texture.png";
    WriteImage((target.parent_path() / texture_name).string(), mesh.texture);
    ply.comments.push_back("TextureFile " + texture_name);
  }
  ply.elements.push_back(std::move(vertex));
  ply.elements.push_back(std::move(face));
  WritePly(path, ply);
}

PointCloud ReadPointCloud(const std::string& path) {
  if (FileExtension(path) != "ply") {
    ThrowInputError(path, "", "",
                    "lidarshop reads point clouds from .ply (use ReadScanFile for .ptx/.pcd/.e57)");
  }
  return PointCloudFromPly(ReadPly(path), path);
}

void WritePointCloud(const std::string& path, const PointCloud& cloud, bool ascii) {
  if (FileExtension(path) != "ply")
    ThrowInputError(path, "", "", "lidarshop writes point clouds as .ply only");
  PlyData ply;
  ply.format = ascii ? PlyData::Format::kAscii : PlyData::Format::kBinaryLittleEndian;
  ply.comments.push_back("written by lidarshop");
  ply.comments.push_back("frame world");
  ply.elements.push_back(VertexElementFromCloud(cloud, /*double_positions=*/false));
  WritePly(path, ply);
}

}  // namespace lidarshop
