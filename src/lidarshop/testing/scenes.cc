#include "lidarshop/testing/scenes.h"

#include "lidarshop/scanner/primitives.h"

#ifndef LIDARSHOP_SOURCE_DIR
#error "LIDARSHOP_SOURCE_DIR must be defined for lidarshop_testing"
#endif

namespace lidarshop::test_scenes {

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

SceneDescription MakeRecolorScene(bool textured, int rows, int columns) {
  SceneDescription scene;
  scene.scanner.position = Eigen::Vector3d(0, 0, 1.5);
  scene.scanner.azimuth_min_deg = -40;
  scene.scanner.azimuth_max_deg = 40;
  scene.scanner.elevation_min_deg = -35;
  scene.scanner.elevation_max_deg = 25;
  scene.scanner.rows = rows;
  scene.scanner.columns = columns;
  const auto add = [&](const std::string& name, const TriangleMesh& mesh, const Eigen::Vector3d& center,
                       int32_t label, Rgb8 color, TextureKind texture) {
    SceneObject object;
    object.name = name;
    object.mesh = mesh;
    object.world_from_object.topRightCorner<3, 1>() = center;
    object.label = label;
    object.material.color = color;
    object.material.texture = texture;
    scene.objects.push_back(object);
  };
  add("ground", MakePlaneMesh(Eigen::Vector2d(60, 60)), Eigen::Vector3d(0, 0, 0), 0, Rgb8(90, 110, 70),
      textured ? TextureKind::kGrass : TextureKind::kNone);
  add("wall", MakeBoxMesh(Eigen::Vector3d(24, 0.4, 6)), Eigen::Vector3d(0, 12.2, 3), 1, Rgb8(200, 190, 160),
      textured ? TextureKind::kBrick : TextureKind::kNone);
  add("box", MakeBoxMesh(Eigen::Vector3d(1.2, 1.2, 1.2)), Eigen::Vector3d(-0.8, 6, 0.6), 2, Rgb8(200, 50, 40),
      TextureKind::kNone);
  add("pillar", MakeBoxMesh(Eigen::Vector3d(0.5, 0.5, 2.5)), Eigen::Vector3d(1.6, 8, 1.25), 3,
      Rgb8(40, 70, 190), TextureKind::kNone);
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

}  // namespace lidarshop::test_scenes
