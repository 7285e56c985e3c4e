#include "lidarshop/testing/random_eval.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"

namespace lidarshop::test_scenes {

void EvalReport::Emit(const std::string& text) {
  fmt::print("{}", text);
  std::fflush(stdout);
  text_ += text;
}

void EvalReport::Write(const std::string& markdown_path) const {
  if (!markdown_path.empty()) WriteFileAtomically(markdown_path, [&](std::ostream& out) { out << text_; });
}

std::vector<uint64_t> ParseSeedRange(const std::string& text, const std::string& flag) {
  auto number = [&](const std::string& part) -> uint64_t {
    size_t used = 0;
    unsigned long long value = 0;
    bool ok = !part.empty() && std::isdigit(static_cast<unsigned char>(part[0]));
    if (ok) {
      try {
        value = std::stoull(part, &used);
      } catch (const std::exception&) {
        ok = false;
      }
    }
    CheckOption(ok && used == part.size(),
                fmt::format("{}: expected N or A..B with whole numbers, got '{}'", flag, text));
    return value;
  };
  const size_t dots = text.find("..");
  uint64_t first = 1, last = 0;
  if (dots == std::string::npos) {
    last = number(text);
  } else {
    first = number(text.substr(0, dots));
    last = number(text.substr(dots + 2));
  }
  CheckOption(first <= last && last - first < 100000,
              fmt::format("{}: expected at least one and at most 100,000 seeds, got '{}'", flag, text));
  std::vector<uint64_t> seeds;
  for (uint64_t seed = first; seed <= last; ++seed) seeds.push_back(seed);
  return seeds;
}

SeedDistribution Distribute(const std::vector<double>& values, const std::vector<uint64_t>& seeds,
                            bool higher_is_better) {
  LIDARSHOP_CHECK(!values.empty() && values.size() == seeds.size());
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const size_t n = sorted.size();
  auto rank = [&](double p) {
    const size_t k = static_cast<size_t>(std::ceil(p * static_cast<double>(n)));
    return sorted[std::clamp<size_t>(k, 1, n) - 1];
  };
  SeedDistribution d;
  d.mean = std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(n);
  d.p5 = rank(0.05);
  d.p95 = rank(0.95);
  const size_t worst = WorstIndices(values, 1, higher_is_better).front();
  d.worst = values[worst];
  d.worst_seed = seeds[worst];
  return d;
}

std::vector<size_t> WorstIndices(const std::vector<double>& values, size_t count, bool higher_is_better) {
  std::vector<size_t> order(values.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return higher_is_better ? values[a] < values[b] : values[a] > values[b];
  });
  order.resize(std::min(count, order.size()));
  return order;
}

namespace {

const SceneObject& TargetPart(const SceneDescription& scene) {
  for (const SceneObject& object : scene.objects) {
    if (object.label == scene.target_label) return object;
  }
  throw std::logic_error("the scene names no target (target_label " + std::to_string(scene.target_label) +
                         ")");
}

}  // namespace

std::string TargetKind(const SceneDescription& scene) {
  std::string name = TargetPart(scene).name;
  name = name.substr(0, name.find('/'));   // "bin_7/lid" -> "bin_7"
  return name.substr(0, name.rfind('_'));  // -> "bin"
}

double TargetDistance(const SceneDescription& scene) {
  TargetPart(scene);
  Eigen::AlignedBox3d box;
  for (const SceneObject& object : scene.objects) {
    if (object.label != scene.target_label) continue;
    for (const Eigen::Vector3f& v : MeshInWorld(object).vertices) box.extend(v.cast<double>());
  }
  return (box.center().head<2>() - scene.scanner.position.head<2>()).norm();
}

bool TargetColouredLikeBackground(const SceneDescription& scene) {
  TargetPart(scene);
  auto background = [](const std::string& name) {
    for (const char* prefix : {"ground_", "wall_", "facade_", "kerb_", "steps_", "ceiling_"}) {
      if (name.rfind(prefix, 0) == 0) return true;
    }
    return false;
  };
  for (const SceneObject& part : scene.objects) {
    if (part.label != scene.target_label) continue;
    for (const SceneObject& other : scene.objects) {
      if (background(other.name) && other.material.color == part.material.color) return true;
    }
  }
  return false;
}

std::string TargetColumn(const SceneDescription& scene) {
  return TargetKind(scene) + (TargetColouredLikeBackground(scene) ? " *" : "");
}

std::string MeanWhere(const std::vector<double>& values, const std::vector<bool>& mask, bool which) {
  LIDARSHOP_CHECK(values.size() == mask.size());
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    if (mask[i] != which) continue;
    sum += values[i];
    ++count;
  }
  return count == 0 ? "0 scenes" : fmt::format("{} scenes, mean {:.3f}", count, sum / count);
}

}  // namespace lidarshop::test_scenes
