// Scene descriptions of the synthetic scanner: objects (meshes in their own frame, a pose, a label, a
// material) and the scanner's settings, read from JSON (docs/scene-format.md has every key, unit, default).
//
//   {"scanner": {"position": [0, 0, 1.5], "rotate_deg": [0, 0, 0], "azimuth_deg": [-45, 45],
//                "elevation_deg": [-30, 30], "columns": 900, "rows": 600, "max_range": 100,
//                "los_noise_sigma": 0.0, "orthogonal_noise_sigma": 0.0, "seed": 1},
//    "objects": [{"primitive": "plane", "size": [200, 200], "label": 0, "texture": "grass"},
//                {"mesh": "meshes/car.obj", "scale": 4.2, "rotate_deg": [90, 0, 30],
//                 "translate": [0, 15, 0]}]}
//
// Transforms: an object is scaled, then rotated (R = Rz * Ry * Rx of `rotate_deg` = [x, y, z] degrees about
// fixed axes), then translated; or given as a 4x4 `matrix` (row-major rows). The scanner's `rotate_deg`
// orients its frame (z up, y forward, x right) in the world the same way; `position` is its world origin.
//
// A site of several stations (docs/stations.md) gives `"stations": [SCANNER, SCANNER, ...]` (each with the
// fields of "scanner") in place of "scanner"; an object may carry `"at_stations": [0, 2]` (default: every
// station), e.g. a car that left between two set-ups. SceneAtStation() gives the one-station scene a station
// sees.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/texture.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// The scanner model (Leica HDS3000-like): a uniform azimuth x elevation grid from one origin.
struct ScannerOptions {
  Eigen::Vector3d position = Eigen::Vector3d(0, 0, 1.5);  // scanner origin in the world, metres
  Eigen::Vector3d rotate_deg =
      Eigen::Vector3d::Zero();       // world_from_scanner rotation, degrees (R = Rz Ry Rx)
  double azimuth_min_deg = -45.0;    // θ of the leftmost column, degrees from +y, positive right
  double azimuth_max_deg = 45.0;     // θ of the rightmost column (> min; at most min + 360)
  double elevation_min_deg = -30.0;  // φ of the bottom row, degrees, positive up, >= -90
  double elevation_max_deg = 30.0;   // φ of the top row (> min), <= 90
  int columns = 900;                 // strips, left to right
  int rows = 600;                    // points per strip
  double max_range_m = 100.0;        // farther hits are no return, metres
  double min_range_m = 0.0;          // nearer hits are ignored (the ray continues), metres
  double los_noise_sigma_m = 0.0;    // σ of the Gaussian error along the ray, metres
  // σ of the Gaussian error perpendicular to the ray (signed length along a direction drawn uniformly in the
  // plane perpendicular to the ray, so the RMS displacement is σ), metres.
  double orthogonal_noise_sigma_m = 0.0;
  uint64_t seed = 1;  // noise seed; same seed = same scan whatever the thread count
  // Intensity model: I = clamp(ρ_eff · |cos α| · exp(-r / intensity_falloff_m), 0, 1) with α the incidence
  // angle and ρ_eff = reflectivity · (0.5 + luminance of the surface colour in [0, 1]); metres.
  double intensity_falloff_m = 150.0;
  // Band-limit procedural textures to each ray's footprint (range · angular step / cos(incidence)), so that
  // detail finer than the ray spacing fades to its mean colour instead of aliasing into moiré at range;
  // false = point-sample the full-detail texture (scanner/texture.h). Not part of scene files.
  bool filter_textures = true;
  // How rays are traced (speed only: every method gives the same hits). Not part of scene files.
  CastMethod cast_method = CastMethod::kPacket16;
  // Which SIMD path shading takes (speed only: the baseline x86-64 path and the AVX2 one give bit-identical
  // scans). kAvx2 = AVX2 where the CPU has it. Not part of scene files.
  SimdPath simd_path = SimdPath::kAvx2;

  void Check() const;  // throws OptionsError
  Eigen::Matrix4d WorldFromScanner() const;
  ScanGrid Grid() const;  // the uniform grid of this scanner (image orientation)
};
template <>
const StructInfo& InfoOf<ScannerOptions>();

struct Material {
  Rgb8 color = Rgb8(180, 180, 180);          // RGB; used where the mesh has no colours of its own
  float reflectivity = 0.5f;                 // Lambertian reflectivity in [0, 1] of a mid-grey surface
  TextureKind texture = TextureKind::kNone;  // procedural texture, coloured from the surface colour
  float texture_scale = 1.0f;                // > 0; 2 = the texture twice as large
};

struct SceneObject {
  std::string name;   // the object's "name", or "objects[i]"
  TriangleMesh mesh;  // in the object frame (unscaled); may carry triangle/vertex colours and a texture
  Eigen::Matrix4d world_from_object = Eigen::Matrix4d::Identity();
  int32_t label = 0;  // in [0, 65534] (65535 marks no return in label PNGs)
  Material material;
  // "at_stations": the stations (indices into SceneDescription::stations) where the object is there; empty =
  // every station.
  std::vector<int> at_stations;

  bool AtStation(int station) const;
};

// What `lidarshop demo` does with a scene (scene key "demo", docs/scene-format.md); "" leaves a step out.
struct SceneDemo {
  std::string cut_object;    // "cut": the object steps 3 and 4 cut out and remove
  std::string sweep_object;  // "sweep"."object": the object whose model step 2b sweeps over the scene
  std::string
      sweep_options_json;  // "sweep"."options": SweepOptions as JSON text (verify/ reads and checks it)
  std::string site;        // "site": a built-in site whose station 0 is this scene (step 4b)
};

struct SceneDescription {
  // The scanner of a one-station scene; with "stations", a copy of stations[0] (so that code that scans one
  // station sees the first).
  ScannerOptions scanner;
  // "stations": every station of a site, in order; empty for a scene with one "scanner" (NumStations() = 1).
  std::vector<ScannerOptions> stations;
  std::vector<SceneObject> objects;
  std::string path;  // the file it was read from ("" when built in code)
  // The object an evaluation strokes or removes (scene key "target_label"): every object with this label;
  // -1 = none named. Random scenes (scanner/random_scene.h) always name one.
  int32_t target_label = -1;
  // What the mesh readers left out of the scene's mesh files (io/mesh_io.h MeshFile::warnings), one sentence
  // each naming the file; not printed by the library.
  std::vector<std::string> warnings;
  SceneDemo demo;  // scene key "demo"

  int64_t NumTriangles() const;
  // The number of stations: stations.size(), or 1 for a scene with one "scanner".
  int NumStations() const;
};

// The one-station scene that station `station` (in [0, NumStations())) sees: its scanner, the objects there
// (at_stations), no `stations`. Throws std::out_of_range for a station the scene does not have.
SceneDescription SceneAtStation(const SceneDescription& scene, int station);

// Reads a scene file. Throws InputError naming the file and the field ("parking_lot.json: objects[2]: field
// 'radius': expected a number > 0, got -1"; unknown keys, missing mesh files and bad types included).
SceneDescription LoadScene(const std::string& path);
// Parses JSON text; `what` names the source in errors, mesh paths are relative to `base_dir`.
SceneDescription ParseScene(const std::string& json_text, const std::string& what,
                            const std::string& base_dir);

// The objects' names by label, for legends (RenderOptions::label_names); objects sharing a label are joined
// with ", ".
std::map<int32_t, std::string> ObjectNamesByLabel(const SceneDescription& scene);

// The mesh of one object of a scene in world coordinates (vertex normals transformed along).
TriangleMesh MeshInWorld(const SceneObject& object);

// The mesh of a primitive, by name, as a scene file would make it ("plane", "box", "sphere", "cylinder",
// "cone", "car", "lamp_post", "electric_box", "mailbox", "facade", "wall"): parameters are a JSON object's
// text, e.g. MakePrimitive("car", R"({"style": "van"})"). For generators and tests.
TriangleMesh MakePrimitive(const std::string& primitive, const std::string& parameters_json = "{}");

}  // namespace lidarshop
