// Triangle meshes and point clouds as files: OBJ (read, with MTL colours and textures) and PLY (read + write,
// ASCII and binary). Point clouds: PLY (read + write). Writers are atomic.
#pragma once

#include <string>
#include <vector>

#include "lidarshop/geometry/mesh.h"

namespace lidarshop {

struct MeshFile {
  std::string path;
  TriangleMesh mesh;
  // What the reader left out of a file it could still read (a missing MTL or texture file, a second
  // texture), one sentence each, starting with the file's path. The library does not print them.
  std::vector<std::string> warnings;
};

// .obj or .ply, by extension. Throws InputError on malformed files (file, line or byte offset, field).
MeshFile ReadMeshFile(const std::string& path);
// ReadMeshFile(path).mesh, for callers that have nowhere to show warnings (they are dropped).
TriangleMesh ReadMesh(const std::string& path);

// .ply (binary little-endian unless `ascii`). Vertex colours, normals and triangle
// colours are written if present.
void WriteMesh(const std::string& path, const TriangleMesh& mesh, bool ascii = false);

// .ply points with whatever per-point fields the cloud has (x y z, nx ny nz, red green blue, intensity,
// label, synthesized). Every point lidarshop writes is in the world frame: the header says so ("comment frame
// world"), and callers give world-frame clouds.
PointCloud ReadPointCloud(const std::string& path);
void WritePointCloud(const std::string& path, const PointCloud& cloud, bool ascii = false);

}  // namespace lidarshop
