// Shared by the automatic resection's test and its evaluation (auto_resection_test.cc,
// eval/auto_resection_eval_main.cc): a random street scene (testing/street_scenes.h) made textured — the
// evaluation's street scenes are uniformly coloured, and a photo of uniform surfaces has nothing a feature
// detector can hold on to beyond a few corners — and a photo from a known camera 0.2–2 m from the scanner.
#pragma once

#include <cstdint>
#include <random>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/testing/street_scenes.h"

namespace lidarshop::testing_auto_resection {

struct AutoCase {
  SceneDescription scene;
  PinholeCamera camera;  // the truth: 800 x 600 px, 70° horizontal field
  double offset_m = 0;   // camera centre to scanner centre
};

// The street scene of `seed` with the ground grass or gravel, the wall brick and each object checker, gravel,
// brick or plain (drawn from the seed, textures 1-4 x their usual size); a scanner of `rows` x `columns` cells over the same field (the
// street scenes' 300 x 450 cells are 0.18° apart, twice a photo pixel); the camera `offset_m` =
// U(0.2, 2.0) m from the scanner, looking 8-12 m ahead (MakeStreetRecolorCase).
inline AutoCase MakeAutoCase(uint64_t seed, int rows = 600, int columns = 900) {
  std::mt19937_64 rng(seed * 7919 + 17);
  std::uniform_real_distribution<double> unit(0, 1);
  AutoCase out;
  out.offset_m = 0.2 + 1.8 * unit(rng);
  test_scenes::StreetRecolorCase street = test_scenes::MakeStreetRecolorCase(seed, out.offset_m);
  out.scene = std::move(street.scene);
  out.camera = street.camera;
  out.scene.scanner.rows = rows;
  out.scene.scanner.columns = columns;
  const TextureKind kinds[] = {TextureKind::kChecker, TextureKind::kGravel, TextureKind::kBrick,
                               TextureKind::kNone};
  for (SceneObject& object : out.scene.objects) {
    // Texture scales of 2-4: the scanner's cells (0.09°, 2-3 cm at 15 m) resolve the pattern; at scale 1 the
    // bricks of a wall 20 m away are filtered to a faint mottle in the scan while the photo still shows them.
    if (object.label == 0) {
      object.material.texture = unit(rng) < 0.5 ? TextureKind::kGrass : TextureKind::kGravel;
      object.material.texture_scale = static_cast<float>(2 + 2 * unit(rng));
    } else if (object.label == 1) {
      object.material.texture = TextureKind::kBrick;
      object.material.texture_scale = static_cast<float>(2.5 + 1.5 * unit(rng));
    } else {
      object.material.texture = kinds[static_cast<int>(unit(rng) * 4) % 4];
      object.material.texture_scale = static_cast<float>(1 + 1.5 * unit(rng));
    }
  }
  return out;
}

// The photo of the case's camera (2 x 2 rays per pixel: anti-aliased like a real lens).
inline Photo AutoCasePhoto(const AutoCase& c) {
  PhotoOptions options;
  options.samples_per_axis = 2;
  options.background = Rgb8(150, 180, 220);
  return RenderPhoto(c.scene, c.camera, options);
}

}  // namespace lidarshop::testing_auto_resection
