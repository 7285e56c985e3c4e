// Internal to the scanner module: the shading of the synthetic scanner, one band of up to 4 image rows at a
// time, over structure-of-arrays buffers, 8 cells per SIMD step (util/simd.h lanes: the baseline and the AVX2
// paths come from one source and give bit-identical scans).
//
// A band goes through: PrepareBand (ray directions, also written to the scan), the cast (scanner.cc fills t,
// geometry, primitive, u, v and the geometric normal), then ShadeBand, row by row:
//   - the row's noise, in a loop of its own (hash -> quantile table);
//   - per group of 8 cells: the objects hit (most groups lie on one object, whose label, reflectivity and
//     colour are then broadcast; curved triangles, mesh colours and image textures are looked up lane by
//     lane), the unit normal facing the scanner, the noisy point and range, procedural textures per object
//     (scanner/texture_lanes.h), intensity, and every output channel of the 8 cells.
// Groups without a return are filled directly. Each step reads the band's arrays and writes the scan's rows,
// so that a GPU back end could run the same steps as kernels.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/simd.h"

namespace lidarshop::scanner_internal {

// Per-object data the shading reads.
struct ObjectData {
  TriangleMesh mesh_in_world;  // vertex normals in the world frame
  Eigen::Matrix3f texture_from_world_rotation;
  Eigen::Vector3f world_origin_of_object;
  Material material;
  int32_t label = 0;
  bool has_texture_image = false;
  // Per triangle: 1 where the vertex normals differ from the face normal (curved surfaces); empty when no
  // triangle is curved (the geometric normal is then exact and no vertex normal is read).
  std::vector<uint8_t> smooth;
  // False when every return has the material colour and the geometric normal (no per-cell lookups).
  bool per_cell = false;

  // Fills the derived fields above from mesh_in_world, material and the object's pose.
  void Prepare(const Eigen::Matrix4d& world_from_object);
};

// The ObjectData of a scene object (mesh in the world, material, label, prepared).
ObjectData MakeObjectData(const SceneObject& object);

// The base colour (packed, scanner/texture.h: PackRgb) of a hit at barycentric (u, v) of `triangle` —
// triangle or vertex colours, image texture, else the material colour; procedural textures come on top of it
// — and, on curved triangles, the interpolated vertex normal (any length); the normal is left alone
// elsewhere. The scanner (per-cell objects) and the synthetic photo (scanner/photo.h) share it.
uint32_t PerCellSurface(const ObjectData& object, int triangle, float u, float v, Eigen::Vector3f* normal);

// What shading needs of one scan, set up once per Acquire.
struct ShadeSetup {
  const ObjectData* objects = nullptr;  // indexed by geometry id
  float world_from_scanner[9] = {};     // row-major rotation
  float scanner_from_world[9] = {};
  float origin[3] = {};  // scanner origin in the world
  float los_sigma = 0, orthogonal_sigma = 0;
  bool noisy = false;
  uint32_t noise_seed[2] = {};
  // Per column (padded to a multiple of 8): sin and cos of the azimuth, in double (the directions are the
  // float of double products, exactly as DirectionsFromGrid) and in float (noise basis). Per row: sin and
  // cos of the elevation.
  std::vector<double> sin_azimuth, cos_azimuth, sin_elevation, cos_elevation;
  std::vector<float> sin_azimuth_f, cos_azimuth_f;
  // exp(-t / falloff) at t = i * max_range / kFalloffSteps (linear interpolation, relative error < 1e-6).
  static constexpr int kFalloffSteps = 1024;
  std::vector<float> falloff;
  float inverse_falloff_step = 0;
  float angular_step_rad = 0;  // the larger grid step (texture footprint); 0 = point-sampled textures
  // Per object: world -> texture coordinates, q = to_texture * (offset + t * w) for a hit at t along the
  // world direction w (offset = scanner origin - object origin), and 1 / texture scale.
  struct TextureFrame {
    float to_texture[9];
    float offset[3];
    float inverse_scale;
  };
  std::vector<TextureFrame> texture_frames;

  ShadeSetup(const std::vector<ObjectData>& objects, const ScannerOptions& options, const ScanGrid& grid,
             const Eigen::Matrix4d& world_from_scanner);
};

// The structure-of-arrays buffers of one band (per thread, reused): cell k = row_in_band * cols + col. Each
// array has 4 * cols cells and 8 of padding, so a SIMD step may read past the end of a row.
struct Band {
  int row0 = 0, rows = 0, cols = 0;
  // Directions of the rays: scanner frame (d) and world frame (w).
  std::vector<float> d_x, d_y, d_z, w_x, w_y, w_z;
  // The cast's results: distance, ids (-1 = no return), barycentric (u, v), normal (world frame, any length;
  // shading turns it into the unit normal facing the scanner).
  std::vector<float> t, u, v, n_x, n_y, n_z;
  std::vector<int32_t> geometry, primitive;
  // The noise of the row being shaded (metres): along the ray, and along b1 and b2 perpendicular to it.
  std::vector<float> noise_los, noise_b1, noise_b2;

  void Resize(int new_cols);
  int cells() const { return rows * cols; }
};

// Fills the band's directions for image rows [row0, row0 + rows) and writes them to scan->direction.
void PrepareBand(const ShadeSetup& setup, int row0, int rows, Band* band, Scan* scan,
                 SimdPath path = BestSimdPath());

// Shades the cast band into the scan's rows (every channel of every cell). Returns the number of returns.
int64_t ShadeBand(const ShadeSetup& setup, Band* band, Scan* scan, SimdPath path = BestSimdPath());

}  // namespace lidarshop::scanner_internal
