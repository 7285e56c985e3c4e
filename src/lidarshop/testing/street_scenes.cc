#include "lidarshop/testing/street_scenes.h"

#include <cmath>
#include <random>
#include <string>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/scanner/primitives.h"

namespace lidarshop::test_scenes {

StreetRecolorCase MakeStreetRecolorCase(uint64_t seed, double camera_offset_m) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  const auto uniform = [&](double low, double high) { return low + (high - low) * unit(rng); };
  const auto colour = [&]() {
    return Rgb8(static_cast<uint8_t>(uniform(20, 235)), static_cast<uint8_t>(uniform(20, 235)),
                static_cast<uint8_t>(uniform(20, 235)));
  };
  StreetRecolorCase out;
  SceneDescription& scene = out.scene;
  scene.scanner.position = Eigen::Vector3d(0, 0, uniform(1.2, 2.0));
  scene.scanner.azimuth_min_deg = -40;
  scene.scanner.azimuth_max_deg = 40;
  scene.scanner.elevation_min_deg = -35;
  scene.scanner.elevation_max_deg = 25;
  scene.scanner.rows = 300;
  scene.scanner.columns = 450;
  scene.scanner.seed = seed;
  int32_t label = 0;
  const auto add = [&](const std::string& name, const TriangleMesh& mesh, const Eigen::Vector3d& at,
                       double yaw_deg, Rgb8 color) {
    SceneObject object;
    object.name = name;
    object.mesh = mesh;
    object.world_from_object = ComposeTransform(at, Eigen::Vector3d(0, 0, yaw_deg));
    object.label = label++;
    object.material.color = color;
    scene.objects.push_back(object);
  };
  const Rgb8 ground = colour();
  // Uniform colours (no procedural texture): the scorer compares the photo's colour with the scan's, and a
  // texture filtered over a photo pixel's footprint differs from the same texture over a scan cell's.
  add("ground", MakePlaneMesh(Eigen::Vector2d(80, 80)), Eigen::Vector3d::Zero(), 0, ground);
  const double wall_y = uniform(14, 24), wall_height = uniform(4, 9);
  if (unit(rng) < 0.5) {
    FacadeMeshOptions facade;
    facade.width = 40;
    facade.height = wall_height;
    facade.wall = colour();
    facade.floors = std::max(1, static_cast<int>(wall_height / 3));
    facade.windows_per_floor = 8;
    add("facade", MakeFacadeMesh(facade), Eigen::Vector3d(0, wall_y, 0), 0, facade.wall);
  } else {
    add("wall", MakeBoxMesh(Eigen::Vector3d(40, 0.4, wall_height)),
        Eigen::Vector3d(0, wall_y + 0.2, wall_height / 2), 0, colour());
  }
  const int objects = 3 + static_cast<int>(unit(rng) * 4);
  for (int i = 0; i < objects; ++i) {
    const double distance = uniform(4, 16), azimuth = uniform(-30, 30) * M_PI / 180;
    const Eigen::Vector3d at(distance * std::sin(azimuth), distance * std::cos(azimuth), 0);
    const double yaw = uniform(0, 360);
    // Some objects take the ground's colour (an object coloured like its background).
    const Rgb8 paint = unit(rng) < 0.2 ? ground : colour();
    switch (static_cast<int>(unit(rng) * 7)) {
      case 0: {  // post
        const double height = uniform(1, 3), radius = uniform(0.04, 0.15);
        add("post", MakeCylinderMesh(radius, height, 24), at + Eigen::Vector3d(0, 0, height / 2), 0, paint);
        break;
      }
      case 1: {  // box on a post
        const double height = uniform(0.8, 1.6), radius = uniform(0.03, 0.06);
        const Eigen::Vector3d box(uniform(0.3, 0.8), uniform(0.3, 0.8), uniform(0.3, 0.7));
        add("box post", MakeCylinderMesh(radius, height, 16), at + Eigen::Vector3d(0, 0, height / 2), 0,
            colour());
        add("box on post", MakeBoxMesh(box), at + Eigen::Vector3d(0, 0, height + box.z() / 2), yaw, paint);
        break;
      }
      case 2: {  // bin
        const double height = uniform(0.7, 1.2);
        add("bin", MakeCylinderMesh(uniform(0.25, 0.4), height, 32), at + Eigen::Vector3d(0, 0, height / 2),
            0, paint);
        break;
      }
      case 3:
        add("cabinet", MakeElectricBoxMesh(paint), at, yaw, paint);
        break;
      case 4: {
        CarMeshOptions car;
        car.style = static_cast<CarStyle>(static_cast<int>(unit(rng) * 3));
        car.paint = paint;
        // At least 6 m out: a car 4.9 m long must not reach the camera beside the scanner.
        add("car", MakeCarMesh(car), at * std::max(1.0, 6.0 / distance), yaw, paint);
        break;
      }
      case 5:
        add("mailbox", MakeMailboxMesh(paint), at, yaw, paint);
        break;
      default: {  // a person-like stack: legs, torso, head
        const double height = uniform(1.5, 1.9);
        add("legs", MakeBoxMesh(Eigen::Vector3d(0.35, 0.25, 0.45 * height)),
            at + Eigen::Vector3d(0, 0, 0.225 * height), yaw, colour());
        add("torso", MakeBoxMesh(Eigen::Vector3d(0.45, 0.28, 0.4 * height)),
            at + Eigen::Vector3d(0, 0, 0.65 * height), yaw, paint);
        add("head", MakeSphereMesh(0.11, 24), at + Eigen::Vector3d(0, 0, 0.85 * height + 0.11), 0, colour());
        break;
      }
    }
  }
  const double side = unit(rng) < 0.5 ? -1 : 1, swing = uniform(-45, 45) * M_PI / 180;
  const Eigen::Vector3d offset =
      camera_offset_m * Eigen::Vector3d(side * std::cos(swing), std::sin(swing), 0) +
      Eigen::Vector3d(0, 0, uniform(0, 0.3));
  const Eigen::Vector3d eye = scene.scanner.position + offset;
  const Eigen::Vector3d target(uniform(-2, 2), uniform(8, 12), uniform(0.5, 1.5));
  out.camera = CameraLookingAt(eye, target, 800, 600, 70);
  return out;
}

}  // namespace lidarshop::test_scenes
