// Synthetic scenes shared by the tests of every module: small scenes whose truth is known, built in code or
// read from the built-in data/scenes/*.json, and scanned with the synthetic scanner (scanner/scanner.h).
//
//   SceneDescription scene = MakeGroundAndBoxScene();  // ground (label 0) + a box (label 1) at y = 8 m
//   Scan scan = ScanScene(scene);                      // 200 x 300 scan, no noise
//   Scan noisy = ScanScene(LoadBuiltinScene("mailbox"), SmallScanner(scene.scanner, 120, 200));
#pragma once

#include <string>

#include <Eigen/Core>

#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"

namespace lidarshop::test_scenes {

struct GroundAndBoxOptions {
  Eigen::Vector3d box_size = Eigen::Vector3d(1.0, 1.0, 1.0);    // metres, x y z
  Eigen::Vector3d box_center = Eigen::Vector3d(0.0, 8.0, 0.5);  // metres, world frame (z = half the height)
  double ground_size = 60.0;                                    // metres, square ground plane at z = 0
  bool ground_texture = true;                                   // grass on the ground, checker on the box
  int rows = 200;
  int columns = 300;
  double azimuth_half_deg = 30.0;  // the scanner looks along +y, azimuth in [-half, half]
  double elevation_min_deg = -30.0;
  double elevation_max_deg = 15.0;
  double scanner_height = 1.5;          // metres
  double los_noise_sigma = 0.0;         // metres
  double orthogonal_noise_sigma = 0.0;  // metres
  uint64_t seed = 1;
};
// A ground plane (label 0, grey or grass) and one box (label 1, red or checker) in front of a scanner at
// (0, 0, scanner_height) looking along +y.
SceneDescription MakeGroundAndBoxScene(const GroundAndBoxOptions& options = {});

// The recolouring scene (recolor/): a uniformly coloured ground (label 0, RGB 90 110 70), a wall 12 m ahead
// (label 1, 200 190 160), a red box (label 2, 200 50 40) and a blue pillar (label 3, 40 70 190) in front of
// it, which hide parts of the wall and ground from a camera beside the scanner; `textured` gives the ground
// grass and the wall bricks instead. Scanner at (0, 0, 1.5) looking along +y, `rows` x `columns` cells over
// azimuth ±40° and elevation -35°..25°.
SceneDescription MakeRecolorScene(bool textured = false, int rows = 300, int columns = 450);

// One object (label `label`) in an otherwise empty world, seen by `scanner`.
SceneDescription MakeSingleObjectScene(const TriangleMesh& mesh_in_world, int32_t label,
                                       const ScannerOptions& scanner, Rgb8 color = Rgb8(200, 60, 50));

// The path of a built-in scene: LIDARSHOP_SOURCE_DIR/data/scenes/<name>.json
// ("parking_lot", "electric_box", "mailbox").
std::string BuiltinScenePath(const std::string& name);
SceneDescription LoadBuiltinScene(const std::string& name);

// `scanner` with another grid size (same angular field and pose); keeps tests fast.
ScannerOptions SmallScanner(const ScannerOptions& scanner, int rows, int columns);

// Scans `scene` with its own scanner settings, or with `scanner`.
Scan ScanScene(const SceneDescription& scene);
Scan ScanScene(const SceneDescription& scene, const ScannerOptions& scanner);

}  // namespace lidarshop::test_scenes
