#include "lidarshop/testing/scenes.h"

#include "lidarshop/scanner/primitives.h"

#ifndef LIDARSHOP_SOURCE_DIR
#error "LIDARSHOP_SOURCE_DIR must be defined for lidarshop_testing"
#endif

namespace lidarshop::testing {

SceneDescription MakeGroundAndBoxScene(const GroundAndBoxOptions& options) {
  SceneDescription scene;
  scene.scanner.position = Eigen::Vector3d(0, 0, options.scanner_height);
  scene.scanner.azimuth_min_deg = -options.azimuth_half_deg;
  scene.scanner.azimuth_max_deg = options.azimuth_half_deg;
  scene.scanner.elevation_min_deg = options.elevation_min_deg;
  scene.scanner.elevation_max_deg = options.elevation_max_deg;
  scene.scanner.rows = options.rows;
  scene.scanner.columns = options.columns;
  scene.scanner.los_noise_sigma_m = options.los_noise_sigma;
  scene.scanner.orthogonal_noise_sigma_m = options.orthogonal_noise_sigma;
  scene.scanner.seed = options.seed;

  SceneObject ground;
  ground.name = "ground";
  ground.mesh = MakePlaneMesh(Eigen::Vector2d(options.ground_size, options.ground_size));
  ground.label = 0;
  ground.material.color =
      options.ground_texture ? DefaultTextureColor(TextureKind::kGrass) : Rgb8(128, 128, 128);
  ground.material.texture = options.ground_texture ? TextureKind::kGrass : TextureKind::kNone;
  scene.objects.push_back(ground);

  SceneObject box;
  box.name = "box";
  box.mesh = MakeBoxMesh(options.box_size);
  box.world_from_object.topRightCorner<3, 1>() = options.box_center;
  box.label = 1;
  box.material.color = Rgb8(200, 50, 40);
  box.material.texture = options.ground_texture ? TextureKind::kChecker : TextureKind::kNone;
  box.material.texture_scale = 0.25f;
  box.material.reflectivity = 0.7f;
  scene.objects.push_back(box);
  return scene;
}

SceneDescription MakeSingleObjectScene(const TriangleMesh& mesh_in_world, int32_t label,
                                       const ScannerOptions& scanner, Rgb8 color) {
  SceneDescription scene;
  scene.scanner = scanner;
  SceneObject object;
  object.name = "object";
  object.mesh = mesh_in_world;
  object.label = label;
  object.material.color = color;
  scene.objects.push_back(object);
  return scene;
}

std::string BuiltinScenePath(const std::string& name) {
  return std::string(LIDARSHOP_SOURCE_DIR) + "/data/scenes/" + name + ".json";
}

SceneDescription LoadBuiltinScene(const std::string& name) { return LoadScene(BuiltinScenePath(name)); }

ScannerOptions SmallScanner(const ScannerOptions& scanner, int rows, int columns) {
  ScannerOptions small = scanner;
  small.rows = rows;
  small.columns = columns;
  return small;
}

Scan ScanScene(const SceneDescription& scene) { return ScanScene(scene, scene.scanner); }

Scan ScanScene(const SceneDescription& scene, const ScannerOptions& scanner) {
  const SyntheticScanner synthetic(scene);
  return synthetic.Acquire(scanner);
}

}  // namespace lidarshop::testing
