// Random street scenes for the recolouring evaluation (issue #30, class 3): ordinary street furniture at
// 4-16 m in front of a scanner, a façade or wall behind, and a camera a few metres beside the scanner that
// looks past the objects' silhouettes onto the ground and wall behind them. Same seed, same scene.
//
//   const StreetRecolorCase c = MakeStreetRecolorCase(7);   // scene, its scanner, a camera 2 m to a side
//   Scan scan = ScanScene(c.scene);
#pragma once

#include <cstdint>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/scanner/scene.h"

namespace lidarshop::test_scenes {

struct StreetRecolorCase {
  SceneDescription scene;  // ground (label 0), a façade or wall 14-24 m ahead (label 1), objects (labels 2..)
  PinholeCamera camera;    // 800 x 600 px, 70° horizontal field, `camera_offset_m` from the scanner
};

// Objects (3-6, drawn from posts, boxes on posts, bins, cabinets, cars, mailboxes, people-like stacks of a
// box and a sphere), random colours (some coloured like the ground), sizes, rotations and distances;
// scanner 1.2-2.0 m above the ground, 300 x 450 cells over azimuth ±40° and elevation -35°..25°. The camera
// is `camera_offset_m` from the scanner in a random horizontal direction (left or right, up to 45° ahead or
// behind), 0-0.3 m higher, looking at a point 8-12 m ahead of the scanner.
StreetRecolorCase MakeStreetRecolorCase(uint64_t seed, double camera_offset_m = 2.0);

}  // namespace lidarshop::test_scenes
