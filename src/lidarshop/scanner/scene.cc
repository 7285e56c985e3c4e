#include "lidarshop/scanner/scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

using nlohmann::json;

std::string TypeName(const json& value) { return value.type_name(); }

// Typed access to one JSON object with errors naming the file, the object and the field.
class Fields {
 public:
  Fields(const json& object, std::string what, std::string place)
      : object_(object), what_(std::move(what)), place_(std::move(place)) {
    if (!object_.is_object()) Fail("", fmt::format("expected a JSON object, got {}", TypeName(object_)));
  }

  [[noreturn]] void Fail(const std::string& field, const std::string& message) const {
    ThrowInputError(what_, place_, field, message);
  }
  void CheckKeys(const std::set<std::string>& allowed) const {
    for (const auto& [key, value] : object_.items()) {
      if (!allowed.contains(key)) {
        std::string list;
        for (const auto& name : allowed) list += (list.empty() ? "" : ", ") + name;
        Fail(key, fmt::format("unknown key (allowed here: {})", list));
      }
    }
  }
  bool Has(const std::string& key) const { return object_.contains(key); }
  const std::string& What() const { return what_; }
  const json& Get(const std::string& key) const { return object_.at(key); }

  double Number(const std::string& key, double fallback) const {
    if (!Has(key)) return fallback;
    const json& value = object_.at(key);
    if (!value.is_number())
      Fail(key, fmt::format("expected a number, got {} {}", TypeName(value), value.dump()));
    const double number = value.get<double>();
    if (!std::isfinite(number)) Fail(key, "not a finite number");
    return number;
  }
  double Positive(const std::string& key, double fallback) const {
    const double number = Number(key, fallback);
    if (!(number > 0)) Fail(key, fmt::format("expected a number > 0, got {}", number));
    return number;
  }
  int64_t Integer(const std::string& key, int64_t fallback, int64_t min, int64_t max) const {
    if (!Has(key)) return fallback;
    const json& value = object_.at(key);
    if (!value.is_number_integer()) {
      Fail(key, fmt::format("expected an integer, got {} {}", TypeName(value), value.dump()));
    }
    const int64_t number = value.get<int64_t>();
    if (number < min || number > max)
      Fail(key, fmt::format("expected an integer in [{}, {}], got {}", min, max, number));
    return number;
  }
  std::string String(const std::string& key, const std::string& fallback) const {
    if (!Has(key)) return fallback;
    const json& value = object_.at(key);
    if (!value.is_string())
      Fail(key, fmt::format("expected a string, got {} {}", TypeName(value), value.dump()));
    return value.get<std::string>();
  }
  std::vector<double> Numbers(const std::string& key, size_t count) const {
    const json& value = object_.at(key);
    if (!value.is_array() || value.size() != count) {
      Fail(key, fmt::format("expected an array of {} numbers, got {}", count, value.dump()));
    }
    std::vector<double> numbers;
    for (const auto& item : value) {
      if (!item.is_number() || !std::isfinite(item.get<double>())) {
        Fail(key, fmt::format("expected an array of {} numbers, got {}", count, value.dump()));
      }
      numbers.push_back(item.get<double>());
    }
    return numbers;
  }
  Eigen::Vector3d Vector3(const std::string& key, const Eigen::Vector3d& fallback) const {
    if (!Has(key)) return fallback;
    const auto numbers = Numbers(key, 3);
    return Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
  }
  Eigen::Vector2d Range(const std::string& key, const Eigen::Vector2d& fallback) const {
    if (!Has(key)) return fallback;
    const auto numbers = Numbers(key, 2);
    if (!(numbers[1] > numbers[0]))
      Fail(key, fmt::format("expected [min, max] with max > min, got {}", Get(key).dump()));
    return Eigen::Vector2d(numbers[0], numbers[1]);
  }
  Rgb8 Color(const std::string& key, Rgb8 fallback) const {
    if (!Has(key)) return fallback;
    const json& value = object_.at(key);
    bool ok = value.is_array() && value.size() == 3;
    if (ok) {
      for (const auto& item : value)
        ok = ok && item.is_number_integer() && item.get<int>() >= 0 && item.get<int>() <= 255;
    }
    if (!ok) Fail(key, fmt::format("expected [r, g, b] with integers in [0, 255], got {}", value.dump()));
    return Rgb8(value[0].get<int>(), value[1].get<int>(), value[2].get<int>());
  }

  const std::string& what() const { return what_; }
  const std::string& place() const { return place_; }

 private:
  const json& object_;
  std::string what_;
  std::string place_;
};

ScannerOptions ParseScanner(const Fields& fields) {
  fields.CheckKeys({"position", "rotate_deg", "azimuth_deg", "elevation_deg", "columns", "rows", "max_range",
                    "min_range", "los_noise_sigma", "orthogonal_noise_sigma", "seed", "intensity_falloff"});
  ScannerOptions options;
  options.position = fields.Vector3("position", options.position);
  options.rotate_deg = fields.Vector3("rotate_deg", options.rotate_deg);
  const Eigen::Vector2d azimuth =
      fields.Range("azimuth_deg", Eigen::Vector2d(options.azimuth_min_deg, options.azimuth_max_deg));
  const Eigen::Vector2d elevation =
      fields.Range("elevation_deg", Eigen::Vector2d(options.elevation_min_deg, options.elevation_max_deg));
  if (azimuth[1] - azimuth[0] > 360.0) {
    fields.Fail("azimuth_deg", "the azimuth range spans more than 360 degrees");
  }
  if (elevation[0] < -90.0 || elevation[1] > 90.0)
    fields.Fail("elevation_deg", "elevations must be in [-90, 90]");
  options.azimuth_min_deg = azimuth[0];
  options.azimuth_max_deg = azimuth[1];
  options.elevation_min_deg = elevation[0];
  options.elevation_max_deg = elevation[1];
  options.columns = static_cast<int>(fields.Integer("columns", options.columns, 2, 100000));
  options.rows = static_cast<int>(fields.Integer("rows", options.rows, 2, 100000));
  if (static_cast<int64_t>(options.columns) * options.rows > (int64_t{1} << 28)) {
    fields.Fail("columns", "columns x rows exceeds 2^28 cells");
  }
  options.max_range_m = fields.Positive("max_range", options.max_range_m);
  options.min_range_m = fields.Number("min_range", options.min_range_m);
  if (options.min_range_m < 0 || options.min_range_m >= options.max_range_m) {
    fields.Fail("min_range", fmt::format("expected 0 <= min_range < max_range, got {}", options.min_range_m));
  }
  options.los_noise_sigma_m = fields.Number("los_noise_sigma", options.los_noise_sigma_m);
  if (options.los_noise_sigma_m < 0) fields.Fail("los_noise_sigma", "expected a number >= 0");
  options.orthogonal_noise_sigma_m =
      fields.Number("orthogonal_noise_sigma", options.orthogonal_noise_sigma_m);
  if (options.orthogonal_noise_sigma_m < 0) fields.Fail("orthogonal_noise_sigma", "expected a number >= 0");
  options.seed = static_cast<uint64_t>(fields.Integer("seed", 1, 0, std::numeric_limits<int64_t>::max()));
  options.intensity_falloff_m = fields.Positive("intensity_falloff", options.intensity_falloff_m);
  return options;
}

const std::set<std::string> kObjectKeys = {
    "primitive",  "mesh",          "name",  "size",         "radius",         "height", "segments",
    "translate",  "rotate_deg",    "scale", "matrix",       "label",          "color",  "reflectivity",
    "texture",    "texture_scale", "style", "subdivisions", "wheel_segments", "floors", "windows_per_floor",
    "at_stations"};

// Primitive meshes from the object's fields; `color_used` is set when the primitive bakes "color" into its
// own triangle colours (composite objects).
constexpr int64_t kMaxSceneTriangles = int64_t{1} << 23;  // ~1.5 GB and seconds to build, not minutes
constexpr int64_t kSceneBytesPerTriangle = 256;           // mesh, colours, Embree's BVH

// Every vertex in the world within kMaxCoordinateM: Embree asserts on huge coordinates (a pose translated by
// 1e308), and no terrestrial scene spans more. Checked in double, before the float mesh is made.
void CheckWorldExtent(const SceneObject& object, const Fields& fields) {
  const Eigen::Matrix4d& m = object.world_from_object;
  const char* key = fields.Has("matrix") ? "matrix" : "translate";
  if (!m.allFinite() || m.topRightCorner<3, 1>().cwiseAbs().maxCoeff() > kMaxCoordinateM) {
    fields.Fail(key, fmt::format("the object's position is beyond {} m", kMaxCoordinateM));
  }
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  for (const Eigen::Vector3f& vertex : object.mesh.vertices) {
    const Eigen::Vector3d world = linear * vertex.cast<double>() + m.topRightCorner<3, 1>();
    if (!(world.cwiseAbs().maxCoeff() <= kMaxCoordinateM)) {
      fields.Fail(fields.Has("scale") ? "scale" : key,
                  fmt::format("a vertex lands at ({}, {}, {}), beyond {} m", world.x(), world.y(), world.z(),
                              kMaxCoordinateM));
    }
  }
}

// Scene complexity is checked before the triangles are made: a scene file of a few hundred bytes (4,096
// spheres of 4,096 segments, cars subdivided 7 times) must fail at once, not after minutes and gigabytes.
// `*scene_triangles` counts the triangles of the objects made so far; `expected` is the next object's.
void CheckSceneTriangles(const Fields& fields, const char* key, int64_t expected, int64_t* scene_triangles) {
  const int64_t total = *scene_triangles + expected;
  if (total > kMaxSceneTriangles) {
    fields.Fail(key, fmt::format("the scene would hold {} triangles, more than the {} accepted", total,
                                 kMaxSceneTriangles));
  }
  try {
    CheckMemoryBudget(SaturatingBytes(total, kSceneBytesPerTriangle),
                      fmt::format("{} scene triangles", total));
  } catch (const InputError& error) {
    fields.Fail(key, error.what());
  }
  *scene_triangles = total;
}

TriangleMesh MakePrimitiveMesh(const std::string& primitive, const Fields& fields, bool* color_used,
                               int64_t* scene_triangles) {
  *color_used = false;
  auto size3 = [&](Eigen::Vector3d fallback) {
    const Eigen::Vector3d size = fields.Vector3("size", fallback);
    if (!(size.minCoeff() > 0)) fields.Fail("size", "expected extents > 0");
    return size;
  };
  const int segments = static_cast<int>(fields.Integer("segments", -1, 3, 4096));
  const int64_t round = segments > 0 ? segments : 96;  // an upper bound of the default segment counts
  if (primitive == "sphere") CheckSceneTriangles(fields, "segments", 2 * round * round, scene_triangles);
  if (primitive == "cylinder" || primitive == "cone" || primitive == "lamp_post" || primitive == "mailbox") {
    CheckSceneTriangles(fields, "segments", 64 * round, scene_triangles);
  }
  if (primitive == "plane") {
    Eigen::Vector2d size(10, 10);
    if (fields.Has("size")) {
      const auto numbers = fields.Numbers("size", 2);
      size = Eigen::Vector2d(numbers[0], numbers[1]);
      if (!(size.minCoeff() > 0)) fields.Fail("size", "expected extents > 0");
    }
    return MakePlaneMesh(size);
  }
  if (primitive == "box") return MakeBoxMesh(size3(Eigen::Vector3d::Ones()));
  if (primitive == "sphere")
    return MakeSphereMesh(fields.Positive("radius", 1.0), segments > 0 ? segments : 96);
  if (primitive == "cylinder") {
    return MakeCylinderMesh(fields.Positive("radius", 0.5), fields.Positive("height", 1.0),
                            segments > 0 ? segments : 64);
  }
  if (primitive == "cone") {
    return MakeConeMesh(fields.Positive("radius", 0.5), fields.Positive("height", 1.0),
                        segments > 0 ? segments : 64);
  }
  if (primitive == "car") {
    CarMeshOptions options;
    options.style = ParseCarStyle(fields.String("style", "sedan"), fields.what() + ": " + fields.place());
    options.paint = fields.Color("color", options.paint);
    options.subdivisions = static_cast<int>(fields.Integer("subdivisions", 0, 0, 7));
    options.wheel_segments = static_cast<int>(fields.Integer("wheel_segments", 48, 8, 4096));
    *color_used = true;
    if (options.subdivisions > 0) {  // each subdivision level quadruples the triangles of the coarse car
      CarMeshOptions coarse = options;
      coarse.subdivisions = 0;
      const int64_t base = static_cast<int64_t>(MakeCarMesh(coarse).triangles.size());
      CheckSceneTriangles(fields, "subdivisions", base << (2 * options.subdivisions), scene_triangles);
    }
    return MakeCarMesh(options);
  }
  if (primitive == "lamp_post") {
    return MakeLampPostMesh(fields.Positive("height", 6.0), segments > 0 ? segments : 24);
  }
  if (primitive == "electric_box") {
    *color_used = true;
    return MakeElectricBoxMesh(fields.Color("color", Rgb8(118, 138, 112)));
  }
  if (primitive == "mailbox") {
    *color_used = true;
    return MakeMailboxMesh(fields.Color("color", Rgb8(60, 62, 66)), segments > 0 ? segments : 24);
  }
  if (primitive == "facade") {
    FacadeMeshOptions options;
    const Eigen::Vector3d size = size3(Eigen::Vector3d(options.width, options.depth, options.height));
    options.width = size.x();
    options.depth = size.y();
    options.height = size.z();
    options.floors = static_cast<int>(fields.Integer("floors", options.floors, 1, 100));
    options.windows_per_floor =
        static_cast<int>(fields.Integer("windows_per_floor", options.windows_per_floor, 1, 200));
    options.wall = fields.Color("color", options.wall);
    *color_used = true;
    try {
      options.Check();
    } catch (const OptionsError& error) {
      fields.Fail("size", error.what());
    }
    constexpr int64_t kTrianglesPerWindow = 64;  // frame, sill, recess and glass, with margin
    CheckSceneTriangles(fields, "windows_per_floor",
                        kTrianglesPerWindow * options.floors * options.windows_per_floor, scene_triangles);
    return MakeFacadeMesh(options);
  }
  if (primitive == "wall") {
    *color_used = true;
    return MakeWallMesh(size3(Eigen::Vector3d(10, 0.3, 2)), fields.Color("color", Rgb8(170, 80, 60)));
  }
  fields.Fail("primitive",
              fmt::format("unknown primitive '{}' (plane, box, sphere, cylinder, cone, car, lamp_post, "
                          "electric_box, mailbox, facade, wall)",
                          primitive));
}

// "at_stations": distinct station indices in [0, num_stations), at least one.
std::vector<int> ParseAtStations(const Fields& fields, int num_stations) {
  if (!fields.Has("at_stations")) return {};
  const json& value = fields.Get("at_stations");
  if (!value.is_array() || value.empty()) {
    fields.Fail("at_stations",
                fmt::format("expected a non-empty array of station indices, got {}", value.dump()));
  }
  std::vector<int> stations;
  for (const json& item : value) {
    if (!item.is_number_integer() || item.get<int64_t>() < 0 || item.get<int64_t>() >= num_stations) {
      fields.Fail("at_stations",
                  fmt::format("expected station indices in [0, {}] (the scene has {} station(s)), "
                              "got {}",
                              num_stations - 1, num_stations, item.dump()));
    }
    const int station = item.get<int>();
    if (std::find(stations.begin(), stations.end(), station) != stations.end())
      fields.Fail("at_stations", fmt::format("station {} is listed twice", station));
    stations.push_back(station);
  }
  std::sort(stations.begin(), stations.end());
  return stations;
}

SceneObject ParseObject(const Fields& fields, size_t index, const std::string& base_dir,
                        int64_t* scene_triangles, std::vector<std::string>* warnings, int num_stations) {
  fields.CheckKeys(kObjectKeys);
  SceneObject object;
  object.at_stations = ParseAtStations(fields, num_stations);
  object.name = fields.String("name", fmt::format("objects[{}]", index));
  const bool has_primitive = fields.Has("primitive"), has_mesh = fields.Has("mesh");
  if (has_primitive == has_mesh) fields.Fail("primitive", "give exactly one of 'primitive' and 'mesh'");
  bool color_used = false;
  if (has_primitive) {
    object.mesh = MakePrimitiveMesh(fields.String("primitive", ""), fields, &color_used, scene_triangles);
  } else {
    const std::string relative = fields.String("mesh", "");
    const std::filesystem::path path = std::filesystem::path(base_dir) / relative;
    std::error_code not_a_file;  // a name too long for the system is not a file either, not a crash
    if (!std::filesystem::is_regular_file(path, not_a_file)) {
      fields.Fail("mesh", fmt::format("mesh file not found: '{}' (paths are relative to the scene file)",
                                      path.string()));
    }
    MeshFile file = ReadMeshFile(path.string());
    object.mesh = std::move(file.mesh);
    warnings->insert(warnings->end(), file.warnings.begin(), file.warnings.end());
    if (fields.Has("color")) {
      object.mesh.triangle_colors.clear();
      object.mesh.vertex_colors.clear();
    }
  }
  // Transform.
  if (fields.Has("matrix")) {
    for (const char* key : {"translate", "rotate_deg", "scale"}) {
      if (fields.Has(key)) fields.Fail("matrix", fmt::format("'matrix' cannot be combined with '{}'", key));
    }
    const json& value = fields.Get("matrix");
    bool ok = value.is_array() && value.size() == 4;
    Eigen::Matrix4d matrix;
    for (int r = 0; ok && r < 4; ++r) {
      ok = value[r].is_array() && value[r].size() == 4;
      for (int c = 0; ok && c < 4; ++c) {
        ok = value[r][c].is_number() && std::isfinite(value[r][c].get<double>());
        if (ok) matrix(r, c) = value[r][c].get<double>();
      }
    }
    if (!ok) fields.Fail("matrix", fmt::format("expected 4 rows of 4 numbers, got {}", value.dump()));
    if ((matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9 ||
        std::abs(matrix.topLeftCorner<3, 3>().determinant()) < 1e-12) {
      fields.Fail("matrix", "expected an invertible affine matrix with last row [0, 0, 0, 1]");
    }
    object.world_from_object = matrix;
  } else {
    Eigen::Vector3d scale = Eigen::Vector3d::Ones();
    if (fields.Has("scale")) {
      const json& value = fields.Get("scale");
      if (value.is_number()) {
        scale.setConstant(value.get<double>());
      } else {
        scale = fields.Vector3("scale", scale);
      }
      if (!(scale.array().abs().minCoeff() > 0)) fields.Fail("scale", "expected non-zero scale factors");
    }
    object.world_from_object = ComposeTransform(fields.Vector3("translate", Eigen::Vector3d::Zero()),
                                                fields.Vector3("rotate_deg", Eigen::Vector3d::Zero()), scale);
  }
  object.label = static_cast<int32_t>(fields.Integer("label", 0, 0, 65534));
  object.material.reflectivity = static_cast<float>(fields.Number("reflectivity", 0.5));
  if (object.material.reflectivity < 0 || object.material.reflectivity > 1) {
    fields.Fail("reflectivity",
                fmt::format("expected a number in [0, 1], got {}", object.material.reflectivity));
  }
  if (fields.Has("texture")) {
    object.material.texture =
        ParseTextureKind(fields.String("texture", ""), fields.what() + ": " + fields.place());
  }
  object.material.texture_scale = static_cast<float>(fields.Positive("texture_scale", 1.0));
  object.material.color = fields.Color("color", object.material.texture != TextureKind::kNone
                                                    ? DefaultTextureColor(object.material.texture)
                                                    : Rgb8(180, 180, 180));
  (void)color_used;
  ValidateMesh(object.mesh, fields.what() + ": " + fields.place());
  if (!has_primitive) {
    CheckSceneTriangles(fields, "mesh", static_cast<int64_t>(object.mesh.triangles.size()), scene_triangles);
  }
  CheckWorldExtent(object, fields);
  return object;
}

// The scene's "demo" object: names of objects the scene has, the sweep's options kept as JSON for verify/.
SceneDemo ParseDemo(const Fields& demo, const SceneDescription& scene) {
  demo.CheckKeys({"cut", "sweep", "site"});
  auto object_name = [&](const Fields& fields, const std::string& key) {
    if (!fields.Has(key)) return std::string();
    const json& value = fields.Get(key);
    if (!value.is_string())
      fields.Fail(key, fmt::format("expected an object's name, got {}", TypeName(value)));
    const std::string name = value.get<std::string>();
    if (std::none_of(scene.objects.begin(), scene.objects.end(),
                     [&](const SceneObject& object) { return object.name == name; })) {
      fields.Fail(key, fmt::format("the scene has no object named '{}'", name));
    }
    return name;
  };
  SceneDemo parsed;
  parsed.cut_object = object_name(demo, "cut");
  if (demo.Has("site")) {
    if (!demo.Get("site").is_string())
      demo.Fail("site", fmt::format("expected a name, got {}", TypeName(demo.Get("site"))));
    parsed.site = demo.Get("site").get<std::string>();
  }
  if (demo.Has("sweep")) {
    const Fields sweep(demo.Get("sweep"), demo.What(), "demo.sweep");
    sweep.CheckKeys({"object", "options"});
    parsed.sweep_object = object_name(sweep, "object");
    if (parsed.sweep_object.empty()) sweep.Fail("object", "missing (the object whose model is swept)");
    if (sweep.Has("options")) {
      if (!sweep.Get("options").is_object())
        sweep.Fail("options", "expected an object of SweepOptions fields");
      parsed.sweep_options_json = sweep.Get("options").dump();
    }
  }
  return parsed;
}

}  // namespace

void ScannerOptions::Check() const {
  Validate(*this);
  CheckOption(position.allFinite() && rotate_deg.allFinite(),
              "scanner: position and rotate_deg must be finite");
  CheckOption(position.cwiseAbs().maxCoeff() <= kMaxCoordinateM && rotate_deg.cwiseAbs().maxCoeff() <= 1e6,
              fmt::format("scanner: position must be within {} m and rotate_deg within 1e6 degrees",
                          kMaxCoordinateM));
  CheckMemoryBudget(SaturatingBytes(int64_t{columns} * rows, 64),
                    fmt::format("a scan of {} rows x {} columns", rows, columns));
}

Eigen::Matrix4d ScannerOptions::WorldFromScanner() const { return ComposeTransform(position, rotate_deg); }

ScanGrid ScannerOptions::Grid() const {
  constexpr double kRad = M_PI / 180.0;
  return UniformGrid(rows, columns, azimuth_min_deg * kRad, azimuth_max_deg * kRad, elevation_min_deg * kRad,
                     elevation_max_deg * kRad);
}

bool SceneObject::AtStation(int station) const {
  return at_stations.empty() ||
         std::find(at_stations.begin(), at_stations.end(), station) != at_stations.end();
}

int SceneDescription::NumStations() const { return stations.empty() ? 1 : static_cast<int>(stations.size()); }

SceneDescription SceneAtStation(const SceneDescription& scene, int station) {
  if (station < 0 || station >= scene.NumStations()) {
    throw std::out_of_range(
        fmt::format("SceneAtStation: station {} of a scene of {} station(s)", station, scene.NumStations()));
  }
  SceneDescription out;
  out.scanner = scene.stations.empty() ? scene.scanner : scene.stations[station];
  out.path = scene.path;
  out.target_label = scene.target_label;
  out.warnings = scene.warnings;
  for (const SceneObject& object : scene.objects) {
    if (object.AtStation(station)) out.objects.push_back(object);
  }
  return out;
}

int64_t SceneDescription::NumTriangles() const {
  int64_t total = 0;
  for (const auto& object : objects) total += static_cast<int64_t>(object.mesh.triangles.size());
  return total;
}

SceneDescription ParseScene(const std::string& json_text, const std::string& what,
                            const std::string& base_dir) {
  // The parsed document takes about 16 bytes per byte of JSON (a node per number, a map per object).
  constexpr int64_t kJsonBytesPerByte = 16;
  CheckMemoryBudget(SaturatingBytes(static_cast<int64_t>(json_text.size()), kJsonBytesPerByte),
                    fmt::format("{}: the scene's JSON ({} bytes)", what, json_text.size()));
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::parse_error& error) {
    ThrowInputError(what, fmt::format("byte {}", error.byte), "",
                    fmt::format("not valid JSON: {}", error.what()));
  } catch (const json::exception& error) {  // e.g. a number past double's range: 1e+315
    ThrowInputError(what, "", "", fmt::format("not usable JSON: {}", error.what()));
  }
  Fields top(root, what, "");
  top.CheckKeys({"scanner", "stations", "objects", "name", "description", "target_label", "demo"});
  SceneDescription scene;
  scene.target_label = static_cast<int32_t>(top.Integer("target_label", -1, 0, 65534));
  if (top.Has("scanner") && top.Has("stations"))
    top.Fail("stations", "give either 'scanner' (one station) or 'stations' (a site), not both");
  if (top.Has("scanner")) scene.scanner = ParseScanner(Fields(top.Get("scanner"), what, "scanner"));
  if (top.Has("stations")) {
    const json& stations = top.Get("stations");
    // A site of a few to hundreds of set-ups; each station is a full scan, so this bounds no real survey.
    constexpr size_t kMaxStations = 1024;
    if (!stations.is_array() || stations.empty() || stations.size() > kMaxStations) {
      top.Fail("stations", fmt::format("expected an array of 1 to {} scanners, got {}", kMaxStations,
                                       stations.is_array() ? fmt::format("{} entries", stations.size())
                                                           : TypeName(stations)));
    }
    for (size_t i = 0; i < stations.size(); ++i) {
      scene.stations.push_back(ParseScanner(Fields(stations[i], what, fmt::format("stations[{}]", i))));
    }
    scene.scanner = scene.stations[0];
  }
  if (!top.Has("objects")) top.Fail("objects", "missing (a list of objects)");
  const json& objects = top.Get("objects");
  if (!objects.is_array()) top.Fail("objects", fmt::format("expected an array, got {}", TypeName(objects)));
  // Every object costs a mesh, a label and an Embree geometry whatever its size (about 5 KB and 0.3 ms: 70,000
  // one-box objects in 1.4 MB took 21 s and 385 MB, 3 million in 65 MB ran past 150 s at 3.3 GB). Scenes are
  // described by tens to thousands of objects.
  constexpr size_t kMaxSceneObjects = size_t{1} << 14;
  if (objects.size() > kMaxSceneObjects) {
    top.Fail("objects",
             fmt::format("{} objects, more than the {} a scene may hold", objects.size(), kMaxSceneObjects));
  }
  int64_t scene_triangles = 0;
  for (size_t i = 0; i < objects.size(); ++i) {
    scene.objects.push_back(ParseObject(Fields(objects[i], what, fmt::format("objects[{}]", i)), i, base_dir,
                                        &scene_triangles, &scene.warnings, scene.NumStations()));
  }
  if (top.Has("demo")) scene.demo = ParseDemo(Fields(top.Get("demo"), what, "demo"), scene);
  if (scene.target_label >= 0 &&
      std::none_of(scene.objects.begin(), scene.objects.end(),
                   [&](const SceneObject& object) { return object.label == scene.target_label; })) {
    top.Fail("target_label", fmt::format("no object has label {}", scene.target_label));
  }
  return scene;
}

SceneDescription LoadScene(const std::string& path) {
  constexpr int64_t kMaxSceneFileBytes = int64_t{16} << 20;  // a scene description, not a mesh
  SceneDescription scene = ParseScene(ReadRegularFile(path, kMaxSceneFileBytes), path,
                                      std::filesystem::path(path).parent_path().string());
  scene.path = path;
  return scene;
}

TriangleMesh MeshInWorld(const SceneObject& object) {
  return TransformMesh(object.mesh, object.world_from_object);
}

TriangleMesh MakePrimitive(const std::string& primitive, const std::string& parameters_json) {
  json parameters = json::parse(parameters_json);
  parameters["primitive"] = primitive;
  Fields fields(parameters, "MakePrimitive", primitive);
  fields.CheckKeys(kObjectKeys);
  bool color_used = false;
  int64_t triangles = 0;
  return MakePrimitiveMesh(primitive, fields, &color_used, &triangles);
}

std::map<int32_t, std::string> ObjectNamesByLabel(const SceneDescription& scene) {
  std::map<int32_t, std::string> names;
  for (const SceneObject& object : scene.objects) {
    std::string& name = names[object.label];
    name += (name.empty() ? "" : ", ") + object.name;
  }
  return names;
}

}  // namespace lidarshop
