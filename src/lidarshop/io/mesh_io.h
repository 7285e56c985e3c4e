// Triangle meshes and point clouds as files: OBJ (read, with MTL colours and textures) and PLY (read + write,
// ASCII and binary). Point clouds: PLY (read + write). Writers are atomic.
#pragma once

#include <string>

#include "lidarshop/geometry/mesh.h"

namespace lidarshop {

// .obj or .ply, by extension. Throws InputError on malformed files (file, line or byte offset, field).
TriangleMesh ReadMesh(const std::string& path);

// .ply (binary little-endian unless `ascii`). Vertex colours, normals and triangle
// colours are written if present.
void WriteMesh(const std::string& path, const TriangleMesh& mesh, bool ascii = false);

// .ply points with whatever per-point fields the cloud has (x y z, nx ny nz, red green blue, intensity,
// label, synthesized).
PointCloud ReadPointCloud(const std::string& path);
void WritePointCloud(const std::string& path, const PointCloud& cloud, bool ascii = false);

}  // namespace lidarshop
