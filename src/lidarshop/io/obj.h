// Wavefront OBJ meshes (read): v (optionally "v x y z r g b" vertex colours in [0, 1]), vt, vn, f (polygons
// are fan-triangulated; v, v/t, v//n, v/t/n and negative indices), mtllib/usemtl with MTL `Kd` colours
// (become triangle_colors) and `map_Kd` textures (the first textured material's image becomes the mesh
// texture; triangles of other materials keep their Kd colour). A missing MTL or texture file is a warning,
// not an error: the geometry is still good. Warnings (one sentence each, starting with the OBJ's path) go to
// `warnings` when it is not null; the library does not print them.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "lidarshop/geometry/mesh.h"

namespace lidarshop {

TriangleMesh ReadObj(const std::string& path, std::vector<std::string>* warnings = nullptr);

// Parses OBJ text; MTL and texture paths are resolved against `folder`. `file` names it in error messages.
TriangleMesh ParseObj(std::string_view text, const std::string& file, const std::string& folder,
                      std::vector<std::string>* warnings = nullptr);

}  // namespace lidarshop
