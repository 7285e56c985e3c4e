#include "lidarshop/scanner/random_scene.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// "bin_7/lid" -> "bin_7": the logical object a part belongs to.
std::string ObjectOf(const std::string& part_name) { return part_name.substr(0, part_name.find('/')); }

bool IsBackground(const std::string& object) {
  for (const char* prefix : {"ground_", "wall_", "facade_", "kerb_", "steps_", "ceiling_"}) {
    if (object.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

// World bounding box of every label's parts.
std::map<int32_t, Eigen::AlignedBox3d> BoundsByLabel(const SceneDescription& scene) {
  std::map<int32_t, Eigen::AlignedBox3d> bounds;
  for (const SceneObject& object : scene.objects) {
    for (const Eigen::Vector3f& v : MeshInWorld(object).vertices)
      bounds[object.label].extend(v.cast<double>());
  }
  return bounds;
}

TEST(RandomScene, SameSeedSameSceneOtherSeedOtherScene) {
  const std::string a = RandomSceneJson(17), b = RandomSceneJson(17);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, RandomSceneJson(18));
  const SceneDescription first = RandomScene(17), second = RandomScene(17);
  ASSERT_EQ(first.objects.size(), second.objects.size());
  EXPECT_EQ(first.target_label, second.target_label);
  for (size_t i = 0; i < first.objects.size(); ++i) {
    EXPECT_EQ(first.objects[i].name, second.objects[i].name);
    EXPECT_EQ(first.objects[i].label, second.objects[i].label);
    EXPECT_EQ(first.objects[i].world_from_object, second.objects[i].world_from_object);
    EXPECT_EQ(first.objects[i].mesh.vertices, second.objects[i].mesh.vertices);
  }
  EXPECT_EQ(first.scanner.azimuth_min_deg, second.scanner.azimuth_min_deg);
  EXPECT_EQ(first.scanner.elevation_max_deg, second.scanner.elevation_max_deg);
}

TEST(RandomScene, JsonReadsBackAsTheSameScene) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / fmt::format("random_scene_test_{}.json", ::getpid());
  {
    std::ofstream out(path);
    out << RandomSceneJson(5);
  }
  const SceneDescription loaded = LoadScene(path.string());
  std::filesystem::remove(path);
  const SceneDescription made = RandomScene(5);
  EXPECT_EQ(loaded.target_label, made.target_label);
  EXPECT_GE(loaded.target_label, 1);
  ASSERT_EQ(loaded.objects.size(), made.objects.size());
  EXPECT_EQ(loaded.NumTriangles(), made.NumTriangles());
  for (size_t i = 0; i < made.objects.size(); ++i) {
    EXPECT_EQ(loaded.objects[i].world_from_object, made.objects[i].world_from_object);
  }
}

TEST(RandomScene, EveryObjectIsSeenAndEveryLabelIsOneObject) {
  const RandomSceneOptions options;
  std::set<std::string> kinds;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE(seed);
    const SceneDescription scene = RandomScene(seed, options);
    // Labels: one per logical object, the target's among them.
    std::map<int32_t, std::string> object_of_label;
    std::map<std::string, int32_t> label_of_object;
    for (const SceneObject& object : scene.objects) {
      const std::string name = ObjectOf(object.name);
      EXPECT_EQ(name.substr(name.rfind('_') + 1), std::to_string(object.label)) << name;
      auto [it, inserted] = object_of_label.emplace(object.label, name);
      EXPECT_EQ(it->second, name) << "label " << object.label << " is on two objects";
      auto [jt, fresh] = label_of_object.emplace(name, object.label);
      EXPECT_EQ(jt->second, object.label) << name << " has two labels";
    }
    ASSERT_TRUE(object_of_label.count(scene.target_label));
    EXPECT_FALSE(IsBackground(object_of_label[scene.target_label]));
    kinds.insert(
        object_of_label[scene.target_label].substr(0, object_of_label[scene.target_label].rfind('_')));

    // Every object has returns in the scan; the target enough of them.
    const Scan scan = SynthesizeScan(scene);
    EXPECT_EQ(scan.cols, options.columns);
    EXPECT_EQ(scan.rows, options.rows);
    std::map<int32_t, int> cells;
    for (int y = 0; y < scan.rows; ++y)
      for (int x = 0; x < scan.cols; ++x)
        if (scan.valid.at<uint8_t>(y, x)) ++cells[scan.label.at<int32_t>(y, x)];
    for (const auto& [label, name] : object_of_label) {
      EXPECT_GE(cells[label], options.min_visible_cells) << name;
    }
    EXPECT_GE(cells[scene.target_label], options.min_target_cells);
  }
  EXPECT_GE(kinds.size(), 5u) << "12 seeds drew too few kinds of target";
}

TEST(RandomScene, DistancesHeightsAndSizesWithinTheirRanges) {
  RandomSceneOptions options;
  options.min_distance_m = 6.0;
  options.max_distance_m = 15.0;
  options.min_scanner_height_m = 1.0;
  options.max_scanner_height_m = 2.0;
  options.indoor_share = 0.0;  // indoors the distance is at most 12 m
  double nearest = 1e9, farthest = 0;
  for (uint64_t seed = 100; seed < 110; ++seed) {
    SCOPED_TRACE(seed);
    const SceneDescription scene = RandomScene(seed, options);
    EXPECT_GE(scene.scanner.position.z(), options.min_scanner_height_m);
    EXPECT_LE(scene.scanner.position.z(), options.max_scanner_height_m);
    EXPECT_EQ(scene.scanner.position.head<2>(), Eigen::Vector2d::Zero());
    const auto bounds = BoundsByLabel(scene);
    // The target's distance is to its footprint's origin, which lies within its bounding box.
    const Eigen::AlignedBox3d& box = bounds.at(scene.target_label);
    const Eigen::Vector2d center = box.center().head<2>();
    const double half_diagonal = box.sizes().head<2>().norm() / 2;
    const double distance = center.norm();
    EXPECT_GE(distance + half_diagonal, options.min_distance_m);
    EXPECT_LE(distance - half_diagonal, options.max_distance_m);
    nearest = std::min(nearest, distance);
    farthest = std::max(farthest, distance);
    std::map<int32_t, std::string> names;
    for (const SceneObject& object : scene.objects) names[object.label] = ObjectOf(object.name);
    for (const auto& [label, b] : bounds) {
      if (IsBackground(names[label])) continue;
      // The catalogue's objects: from a 12 cm ball to a 7 m lamp post.
      EXPECT_GE(b.sizes().maxCoeff(), 0.1) << names[label];
      EXPECT_LE(b.sizes().maxCoeff(), 7.5) << names[label];
      EXPECT_GE(b.min().z(), -1e-3) << names[label] << " below the ground";
    }
  }
  EXPECT_LT(nearest, farthest);
}

TEST(RandomScene, OptionsAreChecked) {
  RandomSceneOptions options;
  options.min_distance_m = 0;
  EXPECT_THROW(RandomSceneJson(1, options), OptionsError);
  options = {};
  options.max_target_share = 0.95;
  EXPECT_THROW(RandomSceneJson(1, options), OptionsError);
  options = {};
  options.columns = 10;
  EXPECT_THROW(RandomSceneJson(1, options), OptionsError);
  options = {};
  options.min_target_cells = 400 * 300 / 20 + 1;  // more than a twentieth of the window
  EXPECT_THROW(RandomSceneJson(1, options), OptionsError);
}

TEST(SceneTargetLabel, MustNameAnObject) {
  const std::string ok = R"({"target_label": 3, "objects": [{"primitive": "box", "label": 3}]})";
  EXPECT_EQ(ParseScene(ok, "t.json", "").target_label, 3);
  EXPECT_EQ(ParseScene(R"({"objects": [{"primitive": "box"}]})", "t.json", "").target_label, -1);
  try {
    ParseScene(R"({"target_label": 4, "objects": [{"primitive": "box", "label": 3}]})", "t.json", "");
    FAIL() << "a target label no object has was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("target_label"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("t.json"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace lidarshop
