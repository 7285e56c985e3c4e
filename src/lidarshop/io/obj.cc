#include "lidarshop/io/obj.h"

#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/image_io.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/text_cursor.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using io_internal::TextCursor;

struct Material {
  Eigen::Vector3f diffuse{0.8f, 0.8f, 0.8f};
  bool has_diffuse = false;
  std::string texture_path;
};

Rgb8 ToRgb8(const Eigen::Vector3f& color) {
  const Eigen::Vector3f scaled = (color.cwiseMax(0.f).cwiseMin(1.f) * 255.f).array().round();
  return Rgb8(static_cast<uint8_t>(scaled.x()), static_cast<uint8_t>(scaled.y()),
              static_cast<uint8_t>(scaled.z()));
}

// The file name at the end of a map_Kd line ("map_Kd -s 1 1 1 wood.png" -> "wood.png").
std::string LastToken(std::string_view line) {
  const size_t space = line.find_last_of(" \t");
  return std::string(space == std::string_view::npos ? line : line.substr(space + 1));
}

// The materials of the MTL file `path`; a file that cannot be read is a warning of the OBJ file `obj_file`
// (null `warnings` = dropped).
void ReadMtl(const std::string& path, const std::string& obj_file, std::map<std::string, Material>* materials,
             std::vector<std::string>* warnings) {
  std::string text;
  try {
    text = io_internal::ReadFileToString(path);
  } catch (const InputError& error) {
    if (warnings != nullptr) {
      warnings->push_back(
          fmt::format("{}: {} (the mesh is read without its materials)", obj_file, error.what()));
    }
    return;
  }
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  TextCursor cursor(text, path);
  Material* current = nullptr;
  while (!cursor.AtEnd()) {
    const std::string_view keyword = cursor.Token();
    if (keyword == "newmtl") {
      current = &(*materials)[std::string(cursor.RestOfLine())];
    } else if (keyword == "Kd" && current != nullptr) {
      current->diffuse.x() = cursor.Float("Kd red");
      current->diffuse.y() = cursor.Float("Kd green");
      current->diffuse.z() = cursor.Float("Kd blue");
      current->has_diffuse = true;
    } else if (keyword == "map_Kd" && current != nullptr) {
      const std::string name = LastToken(cursor.RestOfLine());
      current->texture_path = (folder / name).string();
    }
    cursor.NextLine();
  }
}

// OBJ index (1-based, negative = relative to the end) to 0-based; throws when out of range.
int ResolveIndex(int64_t index, size_t count, const TextCursor& cursor, const char* field) {
  const int64_t resolved = index > 0 ? index - 1 : static_cast<int64_t>(count) + index;
  if (index == 0 || resolved < 0 || resolved >= static_cast<int64_t>(count)) {
    cursor.Fail(field, fmt::format("index {} is outside the {} defined so far", index, count));
  }
  return static_cast<int>(resolved);
}

}  // namespace

TriangleMesh ParseObj(std::string_view text, const std::string& file, const std::string& folder,
                      std::vector<std::string>* warnings) {
  TriangleMesh mesh;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Rgb8> vertex_colors;
  std::map<std::string, Material> materials;
  std::vector<int> triangle_material;  // index into material_names, -1 = none
  std::vector<std::string> material_names;
  int current_material = -1;
  bool any_texcoord = false, any_normal = false;
  std::vector<int> vertex_normal_index;
  TextCursor cursor(text, file);
  std::vector<Eigen::Vector3i> corners;  // vertex, texcoord (-1), normal (-1)
  while (!cursor.AtEnd()) {
    const std::string_view keyword = cursor.Token();
    if (keyword == "v") {
      Eigen::Vector3f v;
      v.x() = cursor.Float("v x");
      v.y() = cursor.Float("v y");
      v.z() = cursor.Float("v z");
      mesh.vertices.push_back(v);
      if (!cursor.AtEndOfLine()) {
        const float first = cursor.Float("v w or red");
        if (!cursor.AtEndOfLine()) {
          Eigen::Vector3f color;
          color.x() = first;
          color.y() = cursor.Float("v green");
          color.z() = cursor.Float("v blue");
          vertex_colors.resize(mesh.vertices.size() - 1, Rgb8(200, 200, 200));
          vertex_colors.push_back(ToRgb8(color));
        }
      }
    } else if (keyword == "vt") {
      Eigen::Vector2f t;
      t.x() = cursor.Float("vt u");
      t.y() = cursor.AtEndOfLine() ? 0.f : cursor.Float("vt v");
      mesh.texcoords.push_back(t);
    } else if (keyword == "vn") {
      Eigen::Vector3f n;
      n.x() = cursor.Float("vn x");
      n.y() = cursor.Float("vn y");
      n.z() = cursor.Float("vn z");
      normals.push_back(n);
    } else if (keyword == "f") {
      corners.clear();
      while (!cursor.AtEndOfLine()) {
        const std::string_view token = cursor.Token();
        Eigen::Vector3i corner(-1, -1, -1);
        size_t start = 0;
        for (int part = 0; part < 3 && start <= token.size(); ++part) {
          size_t slash = token.find('/', start);
          if (slash == std::string_view::npos) slash = token.size();
          const std::string_view number = token.substr(start, slash - start);
          if (!number.empty()) {
            TextCursor sub(number, file, cursor.line());
            static const char* kFields[] = {"f vertex index", "f texcoord index", "f normal index"};
            const int64_t index = sub.Int(kFields[part]);
            const size_t count = part == 0   ? mesh.vertices.size()
                                 : part == 1 ? mesh.texcoords.size()
                                             : normals.size();
            corner[part] = ResolveIndex(index, count, cursor, kFields[part]);
          } else if (part == 0) {
            cursor.Fail("f vertex index", fmt::format("missing in '{}'", io_internal::Printable(token)));
          }
          start = slash + 1;
        }
        corners.push_back(corner);
      }
      if (corners.size() < 3)
        cursor.Fail("f", fmt::format("a face needs 3 corners, found {}", corners.size()));
      for (size_t i = 1; i + 1 < corners.size(); ++i) {
        const Eigen::Vector3i* c[3] = {&corners[0], &corners[i], &corners[i + 1]};
        mesh.triangles.emplace_back((*c[0])[0], (*c[1])[0], (*c[2])[0]);
        const bool textured = (*c[0])[1] >= 0 && (*c[1])[1] >= 0 && (*c[2])[1] >= 0;
        mesh.triangle_texcoords.emplace_back(textured ? Eigen::Vector3i((*c[0])[1], (*c[1])[1], (*c[2])[1])
                                                      : Eigen::Vector3i(-1, -1, -1));
        any_texcoord = any_texcoord || textured;
        triangle_material.push_back(current_material);
      }
      for (const Eigen::Vector3i& corner : corners) {
        if (corner[2] < 0) continue;
        any_normal = true;
        vertex_normal_index.resize(mesh.vertices.size(), -1);
        vertex_normal_index[corner[0]] = corner[2];
      }
    } else if (keyword == "mtllib") {
      const std::string_view names = cursor.RestOfLine();
      ReadMtl((std::filesystem::path(folder) / std::string(names)).string(), file, &materials, warnings);
    } else if (keyword == "usemtl") {
      const std::string name(cursor.RestOfLine());
      auto found = std::find(material_names.begin(), material_names.end(), name);
      current_material = static_cast<int>(found - material_names.begin());
      if (found == material_names.end()) material_names.push_back(name);
    }
    // Other keywords (#, o, g, s, l, vp, ...) carry nothing lidarshop keeps.
    cursor.NextLine();
  }

  if (!vertex_colors.empty()) {
    vertex_colors.resize(mesh.vertices.size(), Rgb8(200, 200, 200));
    mesh.vertex_colors = std::move(vertex_colors);
  }
  if (any_normal) {
    mesh.vertex_normals = ComputeVertexNormals(mesh);
    vertex_normal_index.resize(mesh.vertices.size(), -1);
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
      if (vertex_normal_index[v] >= 0) mesh.vertex_normals[v] = normals[vertex_normal_index[v]].normalized();
    }
  }

  // Materials: Kd colours per triangle; the first textured material provides the texture.
  bool any_material = false;
  int textured_material = -1;
  for (size_t m = 0; m < material_names.size(); ++m) {
    auto found = materials.find(material_names[m]);
    if (found == materials.end()) continue;
    any_material = true;
    if (textured_material < 0 && !found->second.texture_path.empty()) {
      try {
        mesh.texture = ReadImage(found->second.texture_path);
        mesh.texture = io_internal::TextureToRgb8(mesh.texture);
        textured_material = static_cast<int>(m);
      } catch (const InputError& error) {
        if (warnings != nullptr) {
          warnings->push_back(
              fmt::format("{}: {} (the mesh is read without this texture)", file, error.what()));
        }
      }
    } else if (!found->second.texture_path.empty() && textured_material >= 0 && warnings != nullptr) {
      warnings->push_back(
          fmt::format("{}: material '{}' has a second texture; only one texture per mesh is kept", file,
                      material_names[m]));
    }
  }
  if (any_material) {
    mesh.triangle_colors.resize(mesh.triangles.size(), Rgb8(200, 200, 200));
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      if (triangle_material[f] < 0) continue;
      auto found = materials.find(material_names[triangle_material[f]]);
      if (found != materials.end()) mesh.triangle_colors[f] = ToRgb8(found->second.diffuse);
    }
  }
  if (any_texcoord && !mesh.texture.empty()) {
    // Triangles without texture coordinates, or of another material, point at a dummy (0, 0) coordinate.
    const int dummy = static_cast<int>(mesh.texcoords.size());
    mesh.texcoords.emplace_back(0.f, 0.f);
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      if (mesh.triangle_texcoords[f][0] < 0 || triangle_material[f] != textured_material) {
        mesh.triangle_texcoords[f] = Eigen::Vector3i(dummy, dummy, dummy);
      }
    }
  } else {
    mesh.texcoords.clear();
    mesh.triangle_texcoords.clear();
  }
  ValidateMesh(mesh, file);
  return mesh;
}

TriangleMesh ReadObj(const std::string& path, std::vector<std::string>* warnings) {
  const std::string text = io_internal::ReadFileToString(path);
  if (text.empty()) ThrowInputError(path, "line 1", "", "the file is empty (no vertices)");
  return ParseObj(text, path, std::filesystem::path(path).parent_path().string(), warnings);
}

}  // namespace lidarshop
