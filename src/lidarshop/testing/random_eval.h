// What the evaluation programs share when they run on random scenes (scanner/random_scene.h; segment_eval and
// fill_eval --random-seeds): the seed list, the distribution of a score over the seeds (mean, 5th and 95th
// percentile, worst seed) and a description of each scene's target.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lidarshop/scanner/scene.h"

namespace lidarshop::test_scenes {

// The tables an evaluation program prints as it goes (stdout, flushed per piece, so a long run shows its
// progress) and writes whole to its --markdown file at the end (atomically; nothing when the path is empty).
class EvalReport {
 public:
  void Emit(const std::string& text);
  void Write(const std::string& markdown_path) const;

 private:
  std::string text_;
};

// "A..B" (A <= B, both >= 0) or "N" (= 1..N, N >= 1): the seeds in order. Throws OptionsError naming `flag`.
std::vector<uint64_t> ParseSeedRange(const std::string& text, const std::string& flag = "--random-seeds");

struct SeedDistribution {
  double mean = 0;
  double p5 = 0;   // 5th percentile, nearest rank: the ceil(0.05 n)-th smallest value
  double p95 = 0;  // 95th percentile, nearest rank: the ceil(0.95 n)-th smallest value
  double worst = 0;
  uint64_t worst_seed = 0;
};
// `values[i]` belongs to `seeds[i]`; the worst is the smallest value when higher is better, else the largest.
// Throws std::logic_error on empty or mismatched inputs.
SeedDistribution Distribute(const std::vector<double>& values, const std::vector<uint64_t>& seeds,
                            bool higher_is_better);
// Indices of the `count` worst values (fewer when there are fewer), worst first; ties by index.
std::vector<size_t> WorstIndices(const std::vector<double>& values, size_t count, bool higher_is_better);

// The target's kind and horizontal distance: "bin" and the distance from the scanner to the centre of the
// bounding box of the objects labelled scene.target_label, metres. Throws std::logic_error without a target.
std::string TargetKind(const SceneDescription& scene);
double TargetDistance(const SceneDescription& scene);
// True when a part of the target has the colour of the ground, a wall, a façade, a kerb, steps or a ceiling
// (objects named "ground_...", "wall_...", ...: the random scenes' background), as a quarter of them do.
bool TargetColouredLikeBackground(const SceneDescription& scene);
// The target column of the evaluations' tables: TargetKind, with " *" when coloured like its background.
std::string TargetColumn(const SceneDescription& scene);
// "N scenes, mean M" of `values` over the seeds where `mask` is `which`, for the evaluations' summaries.
std::string MeanWhere(const std::vector<double>& values, const std::vector<bool>& mask, bool which);

}  // namespace lidarshop::test_scenes
