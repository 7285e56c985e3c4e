// Random scenes: street and indoor scenes no one tuned an algorithm on, assembled from parametrised parts, for
// measuring quality on scenes built elsewhere (issue 30; segment_eval / fill_eval --random-seeds,
// `lidarshop scan --random SEED`).
//
// A scene is a ground (grass, gravel, paving, asphalt; indoors a tiled or plain floor), usually a background
// (a façade with recessed windows, a brick or plain wall with a recess; indoors walls and sometimes a side wall
// and a ceiling), sometimes a kerb with a raised pavement or steps, one target object and up to
// `max_neighbours` other objects beside it, touching it, behind it or against the wall. Objects come from a
// catalogue of parts: a box on a post overhanging towards the scanner, a sign on a post, tables (a top over
// legs), chairs, benches, bins, crates, balls, traffic cones, bollards, cars, people (stacks of boxes and a
// sphere), electric cabinets, mailboxes, lamp posts. Colours are random per part (objects of several
// colours), and in some scenes the target takes the colour of its background.
//
// Frames and units: metres, world z up. The scanner stands at (0, 0, h), unrotated (+y forward); its window
// (azimuth x elevation, square cells, `columns` x `rows`) is centred on the target and its angular step chosen
// so that the target spans between `min_target_share` and `max_target_share` of the window: the target's
// cells are as many at 40 m as at 2 m, as in a crop of a dense scan. The target's distance (horizontal,
// scanner to the centre of its footprint) is drawn log-uniformly in [min_distance_m, max_distance_m] (within
// 12 m indoors), so near and far scenes are equally common.
//
// Every logical object has its own label (1, 2, ...); its parts share it and are named "<kind>_<label>/<part>"
// (the ground, walls, kerbs, steps and ceilings are named "ground_<label>", "wall_<label>", ...). The target's
// label is SceneDescription::target_label. Objects that would leave fewer than `min_visible_cells` returns in
// the window (hidden or outside it) are left out: the generator scans the scene once to check.
//
// Deterministic: the same seed and options give the same JSON on any CPU and compiler: a std::mt19937_64,
// whose sequence the standard fixes, mapped to numbers by hand (not by std::*_distribution, whose mapping is
// the library's own), every draw in its own statement (argument evaluation order is unspecified), and the
// numbers of the JSON rounded to 0.1 mm and 0.001°, which hides the last-bit differences sin, cos, exp and
// atan2 may have between C libraries (all but exact ties). The visibility scan is the scanner's, bit-identical
// on every CPU.
#pragma once

#include <cstdint>
#include <string>

#include "lidarshop/scanner/scene.h"

namespace lidarshop {

struct RandomSceneOptions {
  int columns = 400;                  // scanner window, cells (>= 64)
  int rows = 300;                     // (>= 64)
  double min_distance_m = 2.0;        // target distance from the scanner, metres (> 0)
  double max_distance_m = 40.0;       // (>= min_distance_m)
  double min_scanner_height_m = 0.4;  // scanner origin above the ground, metres (> 0)
  double max_scanner_height_m = 3.0;  // (>= min_scanner_height_m)
  double min_target_share = 0.2;      // the target spans this share of the window's width or height, at least
  double max_target_share = 0.45;     // at most (in (0, 0.9])
  int max_neighbours = 4;             // other objects near the target (0..16)
  double indoor_share = 0.3;          // share of indoor scenes, in [0, 1]
  double los_noise_sigma_m = 0.003;   // scanner noise along the ray, metres (>= 0)
  double orthogonal_noise_sigma_m = 0.0015;  // across the ray, metres (>= 0)
  int min_visible_cells = 20;                // objects with fewer returns in the window are left out
  int min_target_cells = 400;                // a draw whose target has fewer returns is drawn again

  void Check() const;  // throws OptionsError
};

// The scene of `seed` as scene-file JSON (docs/scene-format.md; "target_label" names the target): what
// `lidarshop scan --random SEED --write-scene FILE` writes, and LoadScene reads back to the same scene.
std::string RandomSceneJson(uint64_t seed, const RandomSceneOptions& options = {});

// ParseScene(RandomSceneJson(seed, options)): the scene with its scanner, labels and target_label.
SceneDescription RandomScene(uint64_t seed, const RandomSceneOptions& options = {});

}  // namespace lidarshop
