// Turning PLY tables into lidarshop containers and back (internal to the io module; see ply.h for the
// property names lidarshop uses).
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/io/ply.h"

namespace lidarshop::io_internal {

// The element called `name`; throws InputError naming the file when it is missing.
const PlyElement& RequireElement(const PlyData& ply, const std::string& name, const std::string& file);

// The first scalar property of `element` with one of `names`, or nullptr.
const PlyProperty* FindScalar(const PlyElement& element, std::initializer_list<const char*> names);

// (a, b, c) of every record; empty when the properties are absent (InputError when `required`).
std::vector<Eigen::Vector3f> Vector3Property(const PlyElement& element, const char* a, const char* b,
                                             const char* c, const std::string& file, bool required);

// red/green/blue (or r/g/b, diffuse_red/...) of every record as 0-255; float colours in [0, 1] are scaled.
std::vector<Rgb8> ColorProperty(const PlyElement& element);

void AddScalarProperty(PlyElement* element, const std::string& name, PlyType type,
                       std::vector<double> values);
void AddVector3Property(PlyElement* element, const std::vector<Eigen::Vector3f>& values, const char* a,
                        const char* b, const char* c, PlyType type = PlyType::kFloat32);
void AddColorProperty(PlyElement* element, const std::vector<Rgb8>& colors);

// The vertices' channels as a cloud; its points are x y z as floats (InputError without them), or empty when
// not `require_positions` (the caller reads VertexPositions).
PointCloud PointCloudFromPly(const PlyData& ply, const std::string& file, bool require_positions = true);

// x y z of every record of `vertex` in the file's precision (double): InputError naming the file without x or
// y, or for a coordinate not finite or beyond kMaxCoordinateM (naming the vertex); without z (PDAL writes
// such files) z = 0 and `warnings` (optional) says so.
std::vector<Eigen::Vector3d> VertexPositions(const PlyElement& vertex, const std::string& file,
                                             std::vector<std::string>* warnings);
// The "vertex" element of a cloud: x y z (double when `double_positions`), normals, colours, intensity,
// label, synthesized.
PlyElement VertexElementFromCloud(const PointCloud& cloud, bool double_positions);

}  // namespace lidarshop::io_internal
