// Internal to scanner/: the catalogue of parametrised objects random scenes are assembled from
// (scanner/random_scene.h), and the seeded number source they draw from.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "lidarshop/geometry/mesh.h"

namespace lidarshop::random_scene {

// Uniform numbers from a std::mt19937_64 (its sequence is fixed by the standard) mapped by hand, so that the
// same seed draws the same numbers with every standard library.
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  double Uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  int Int(int lo, int hi) {  // in [lo, hi]
    return lo + static_cast<int>(engine_() % static_cast<uint64_t>(hi - lo + 1));
  }
  bool Chance(double p) { return Uniform(0, 1) < p; }
  template <class T>
  const T& Pick(const std::vector<T>& items) {
    return items[static_cast<size_t>(Int(0, static_cast<int>(items.size()) - 1))];
  }
  // A colour of random hue, saturation and value (greys included), RGB.
  Rgb8 Color();

 private:
  std::mt19937_64 engine_;
};

// One primitive of an object, in the object's frame (z up, standing on z = 0, front towards -y).
struct Part {
  std::string name;       // "post", "top", ...
  std::string primitive;  // a scene primitive: box, cylinder, sphere, cone, car, mailbox, ...
  nlohmann::ordered_json parameters = nlohmann::ordered_json::object();  // size, radius, height, style...
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // where the primitive's origin goes, metres
  Rgb8 color = Rgb8(180, 180, 180);
  bool main = true;  // takes the object's colour when the scene colours it like its background
};

// A logical object: its parts and its bounding box in its own frame.
struct Thing {
  std::string kind;  // "table", "person", ...
  std::vector<Part> parts;
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();  // metres, object frame
};

// The kinds MakeThing knows: street objects and indoor objects (some in both).
const std::vector<std::string>& StreetKinds();
const std::vector<std::string>& IndoorKinds();
const std::vector<std::string>& StreetNeighbourKinds();  // StreetKinds plus lamp posts

// An object of `kind` with random sizes and colours; its bounding box is computed from its parts.
Thing MakeThing(const std::string& kind, Rng* rng);

}  // namespace lidarshop::random_scene
