// PLY (Stanford polygon file format): a header of elements and typed properties, then ASCII or binary
// (little- or big-endian) records. This layer reads and writes the generic tables; mesh_io.h and scan_io.h
// build meshes, point clouds and scans from them.
//
// lidarshop's own conventions inside PLY:
//   vertex:   x y z, nx ny nz, red green blue (uchar), intensity (float), label (int), synthesized (uchar),
//             true_range (float); for scans also row, col (int, image orientation) and scan (int, index in
//             the file)
//   face:     vertex_indices (list uchar int), red green blue (uchar), texcoord (list uchar float: u v per
//             corner)
//   comments  "frame world" (every point lidarshop writes is in the world frame), "lidarshop_scan <index>
//             <rows> <cols> <16 numbers: world_from_scanner, row-major>" for each scan (the points themselves
//             are in the world frame), "TextureFile <name>" for a mesh texture.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lidarshop {

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the value type (of a list's items)
  bool is_list = false;
  PlyType count_type = PlyType::kUInt8;  // lists only
  // Scalar property: one value per record. List property: `offsets` has #records + 1 entries into `values`.
  std::vector<double> values;
  std::vector<int64_t> offsets;
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> properties;

  // The property called `name`, or nullptr.
  const PlyProperty* Find(const std::string& name) const;
};

struct PlyData {
  enum class Format { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
  Format format = Format::kBinaryLittleEndian;
  std::vector<std::string> comments;  // without the "comment " prefix
  std::vector<PlyElement> elements;

  // The element called `name`, or nullptr.
  const PlyElement* Find(const std::string& name) const;
};

// Reads every element. Throws InputError naming the file, the line (header, ASCII) or byte
// offset (binary) and the property; element counts that cannot fit in the rest of the file are
// refused before anything is allocated.
PlyData ReadPly(const std::string& path);
PlyData ParsePly(const std::string& bytes, const std::string& file);
// The header alone (elements with their counts and properties, comments; no values), read from the start of
// the file; `data_bytes` (optional) gets the number of bytes after the header. Throws InputError as ReadPly.
PlyData ReadPlyHeader(const std::string& path, int64_t* data_bytes = nullptr);

// Writes `data` in its format (ASCII or binary little-endian; big-endian is
// written as little-endian). Atomic.
void WritePly(const std::string& path, const PlyData& data);

}  // namespace lidarshop
