#include "lidarshop/scanner/random_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/scanner/random_scene_parts.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using OrderedJson = nlohmann::ordered_json;
using random_scene::Part;
using random_scene::Rng;
using random_scene::Thing;

constexpr double kDeg = M_PI / 180.0;

// Numbers in the JSON: metres to 0.1 mm, degrees to 0.001°, so that the text (and the scene read back from
// it) does not carry the last bits of sin / cos / atan2, which may differ between C libraries.
double Metres(double v) { return std::round(v * 1e4) / 1e4; }
double Degrees(double v) { return std::round(v * 1e3) / 1e3; }
OrderedJson Array3(const Vector3d& v) { return {Metres(v.x()), Metres(v.y()), Metres(v.z())}; }
OrderedJson Color(Rgb8 c) { return {c[0], c[1], c[2]}; }

// An object placed in the world: position of its frame's origin (footprint centre on its base), yaw.
struct Placed {
  Thing thing;
  Vector3d position = Vector3d::Zero();
  double yaw_deg = 0;
  int32_t label = 0;
  std::string name;

  Vector2d ToWorld(const Vector2d& local) const {
    const double c = std::cos(yaw_deg * kDeg), s = std::sin(yaw_deg * kDeg);
    return position.head<2>() + Vector2d(c * local.x() - s * local.y(), s * local.x() + c * local.y());
  }
  std::array<Vector2d, 4> Footprint() const {
    return {ToWorld({thing.min.x(), thing.min.y()}), ToWorld({thing.max.x(), thing.min.y()}),
            ToWorld({thing.max.x(), thing.max.y()}), ToWorld({thing.min.x(), thing.max.y()})};
  }
  std::array<Vector3d, 8> Corners() const {
    std::array<Vector3d, 8> corners;
    const auto foot = Footprint();
    for (int i = 0; i < 8; ++i) {
      corners[i] << foot[i % 4], position.z() + (i < 4 ? thing.min.z() : thing.max.z());
    }
    return corners;
  }
  void Bounds2(double* x0, double* x1, double* y0, double* y1) const {
    *x0 = *y0 = 1e9;
    *x1 = *y1 = -1e9;
    for (const Vector2d& p : Footprint()) {
      *x0 = std::min(*x0, p.x()), *x1 = std::max(*x1, p.x());
      *y0 = std::min(*y0, p.y()), *y1 = std::max(*y1, p.y());
    }
  }
};

// Separating-axis test of two footprints (convex quadrilaterals): true when they overlap by more than 1 mm
// (touching footprints do not overlap).
bool Overlap(const std::array<Vector2d, 4>& a, const std::array<Vector2d, 4>& b) {
  for (const auto* shape : {&a, &b}) {
    for (int i = 0; i < 4; ++i) {
      const Vector2d edge = (*shape)[(i + 1) % 4] - (*shape)[i];
      const Vector2d axis = Vector2d(-edge.y(), edge.x()).normalized();
      double a0 = 1e18, a1 = -1e18, b0 = 1e18, b1 = -1e18;
      for (const Vector2d& p : a) a0 = std::min(a0, axis.dot(p)), a1 = std::max(a1, axis.dot(p));
      for (const Vector2d& p : b) b0 = std::min(b0, axis.dot(p)), b1 = std::max(b1, axis.dot(p));
      if (a1 < b0 + 1e-3 || b1 < a0 + 1e-3) return false;
    }
  }
  return true;
}

void Emit(const Placed& placed, OrderedJson* objects) {
  for (const Part& part : placed.thing.parts) {
    const Vector2d xy = placed.ToWorld(part.center.head<2>());
    OrderedJson object;
    object["name"] = placed.name + "/" + part.name;
    object["primitive"] = part.primitive;
    for (const auto& [key, value] : part.parameters.items()) {
      object[key] = value.is_number_float() ? OrderedJson(Metres(value.get<double>())) : value;
      if (key == "size") {
        object[key] = OrderedJson::array();
        for (const auto& v : value) object[key].push_back(Metres(v.get<double>()));
      }
    }
    object["translate"] = Array3(Vector3d(xy.x(), xy.y(), placed.position.z() + part.center.z()));
    object["rotate_deg"] = {0, 0, Degrees(placed.yaw_deg)};
    object["label"] = placed.label;
    object["color"] = Color(part.color);
    objects->push_back(std::move(object));
  }
}

// A background part (ground, wall, ...) as one scene object.
OrderedJson Background(const std::string& name, const std::string& primitive, int32_t label, Rgb8 color) {
  OrderedJson object;
  object["name"] = name;
  object["primitive"] = primitive;
  object["label"] = label;
  object["color"] = Color(color);
  return object;
}

struct Draft {
  OrderedJson root;
  int32_t target_label = 0;
  std::string target_kind;
  double target_distance_m = 0;
};

Draft Draw(Rng* rng, const RandomSceneOptions& o, uint64_t seed) {
  const bool indoor = rng->Chance(o.indoor_share);
  int32_t next_label = 1;
  OrderedJson objects = OrderedJson::array();

  // The target: its kind, its distance (log-uniform, at least twice its size), its bearing and yaw.
  Placed target;
  target.thing = random_scene::MakeThing(
      rng->Pick(indoor ? random_scene::IndoorKinds() : random_scene::StreetKinds()), rng);
  const double extent = (target.thing.max - target.thing.min).maxCoeff();
  const double far = indoor ? std::min(o.max_distance_m, 12.0) : o.max_distance_m;
  const double near = std::min(far, std::max(o.min_distance_m, 2.0 * extent));
  const double distance = std::exp(rng->Uniform(std::log(near), std::log(far)));
  const double bearing = rng->Uniform(-25, 25) * kDeg;
  target.position = Vector3d(distance * std::sin(bearing), distance * std::cos(bearing), 0);
  const double facing = std::atan2(-target.position.x(), target.position.y()) / kDeg;  // front to the scanner
  target.yaw_deg = target.thing.kind == "car" ? rng->Uniform(0, 360) : facing + rng->Uniform(-25, 25);
  target.label = 0;  // numbered after the background
  const double height = indoor ? rng->Uniform(std::max(o.min_scanner_height_m, 0.8),
                                              std::max(std::min(o.max_scanner_height_m, 1.8),
                                                       std::max(o.min_scanner_height_m, 0.8)))
                               : rng->Uniform(o.min_scanner_height_m, o.max_scanner_height_m);
  double tx0, tx1, ty0, ty1;
  target.Bounds2(&tx0, &tx1, &ty0, &ty1);

  // Kerb (street): the target on a raised pavement, or before the kerb with the pavement behind it.
  const bool kerb = !indoor && rng->Chance(0.4);
  const double kerb_height = kerb ? rng->Uniform(0.1, 0.2) : 0.0;
  const bool on_pavement = kerb && rng->Chance(0.5);
  const double kerb_y = !kerb         ? 1e9
                        : on_pavement ? ty0 - rng->Uniform(0.3, 2.5)
                                      : ty1 + rng->Uniform(0.1, 1.5);
  auto base_z = [&](double y0, double y1) { return kerb && y0 >= kerb_y ? kerb_height : 0.0; };
  target.position.z() = base_z(ty0, ty1);

  // Background: a wall behind the target (sometimes touching it), steps before it.
  const bool back = indoor || rng->Chance(0.85);
  double back_y = 1e9;
  int steps = 0;
  double rise = 0, tread = 0;
  if (back) {
    back_y = ty1 + (rng->Chance(0.2) ? 0.0 : rng->Uniform(0.3, indoor ? 2.5 : 6.0));
    if (kerb && !on_pavement && back_y < kerb_y + 0.5) back_y = kerb_y + rng->Uniform(0.5, 3.0);
    if (!indoor && !kerb && rng->Chance(0.3)) {
      steps = rng->Int(2, 4);
      rise = rng->Uniform(0.14, 0.19);
      tread = rng->Uniform(0.28, 0.35);
      back_y = std::max(back_y, ty1 + steps * tread + rng->Uniform(0.1, 1.0));
    }
  }
  const double front_limit = back_y - steps * tread;  // objects stand before this y

  // The window: centred on the target, its step so that the target spans the drawn share of it.
  double az0 = 1e9, az1 = -1e9, el0 = 1e9, el1 = -1e9;
  for (const Vector3d& c : target.Corners()) {
    az0 = std::min(az0, std::atan2(c.x(), c.y()) / kDeg),
    az1 = std::max(az1, std::atan2(c.x(), c.y()) / kDeg);
    const double el = std::atan2(c.z() - height, c.head<2>().norm()) / kDeg;
    el0 = std::min(el0, el), el1 = std::max(el1, el);
  }
  const double share = rng->Uniform(o.min_target_share, o.max_target_share);
  double step = std::max((az1 - az0) / (share * (o.columns - 1)), (el1 - el0) / (share * (o.rows - 1)));
  step = std::clamp(step, 0.002, std::min(150.0 / (o.columns - 1), 170.0 / (o.rows - 1)));
  const double az_span = step * (o.columns - 1), el_span = step * (o.rows - 1);
  double window_az0 = az0 - std::max(0.0, az_span - (az1 - az0)) * rng->Uniform(0.3, 0.7);
  if (az_span < az1 - az0) window_az0 = (az0 + az1 - az_span) / 2;
  // The target in the upper middle: more room below it (ground, kerb) than above.
  double window_el1 = el1 + std::max(0.0, el_span - (el1 - el0)) * rng->Uniform(0.15, 0.35);
  if (el_span < el1 - el0) window_el1 = (el0 + el1 + el_span) / 2;
  window_el1 = std::clamp(window_el1, -90.0 + el_span, 90.0);
  const double window_el0 = window_el1 - el_span;
  // Where the window meets a wall at depth y: x from y tan(az0) to y tan(az1), with margin.
  auto x_range = [&](double y, double* x0, double* x1) {
    *x0 = y * std::tan(std::max(window_az0, -80.0) * kDeg) - 2.0;
    *x1 = y * std::tan(std::min(window_az0 + az_span, 80.0) * kDeg) + 2.0;
  };

  // Ground.
  const double ground_size = 2 * std::max(distance, back ? back_y : distance) + 80.0;
  {
    OrderedJson ground =
        Background(fmt::format("ground_{}", next_label), "plane", next_label, Rgb8(120, 120, 120));
    ground["size"] = {Metres(ground_size), Metres(ground_size)};
    ground["translate"] = Array3(Vector3d(0, distance, 0));
    const int look = rng->Int(0, 3);
    if (indoor) {
      if (look < 2) {
        ground["texture"] = "checker";
        ground["texture_scale"] = Metres(rng->Uniform(0.3, 0.6));
      }
      ground["color"] =
          Color(rng->Chance(0.5) ? Rgb8(static_cast<uint8_t>(rng->Int(120, 180)), 100, 70) : rng->Color());
    } else if (look == 0) {
      ground["texture"] = "grass";
      const int r = rng->Int(60, 100), g = rng->Int(95, 130), b = rng->Int(30, 60);
      ground["color"] =
          Color(Rgb8(static_cast<uint8_t>(r), static_cast<uint8_t>(g), static_cast<uint8_t>(b)));
    } else if (look == 1) {
      ground["texture"] = "gravel";
      const uint8_t v = static_cast<uint8_t>(rng->Int(100, 150));
      ground["color"] = Color(Rgb8(v, v, static_cast<uint8_t>(v - 10)));
    } else if (look == 2) {
      ground["texture"] = "checker";
      ground["texture_scale"] = Metres(rng->Uniform(0.3, 0.6));
      ground["color"] = Color(rng->Color());
    } else {
      const uint8_t v = static_cast<uint8_t>(rng->Int(55, 100));
      ground["color"] = Color(Rgb8(v, v, v));  // asphalt
    }
    objects.push_back(ground);
    ++next_label;
  }
  const OrderedJson ground_color = objects.back()["color"];

  if (kerb) {  // the pavement: a slab from the kerb back (to the wall or 8 m), its front face the kerb
    double x0, x1;
    const double depth = back ? back_y - kerb_y : 8.0;
    x_range(kerb_y + depth, &x0, &x1);
    const int32_t label = next_label++;
    OrderedJson pavement = Background(fmt::format("kerb_{}", label), "box", label, rng->Color());
    pavement["size"] = {Metres(x1 - x0 + 4), Metres(depth), Metres(kerb_height)};
    pavement["translate"] = Array3(Vector3d((x0 + x1) / 2, kerb_y + depth / 2, kerb_height / 2));
    if (rng->Chance(0.5)) pavement["texture"] = "checker", pavement["texture_scale"] = 0.3;
    objects.push_back(pavement);
  }

  OrderedJson wall_color = ground_color;
  if (back) {
    double x0, x1;
    x_range(back_y, &x0, &x1);
    const double width = std::max(4.0, x1 - x0), center_x = (x0 + x1) / 2;
    const int style = rng->Int(0, 2);
    const int32_t label = next_label++;
    const Rgb8 color = rng->Color();
    wall_color = Color(color);
    if (style == 0) {  // a façade with recessed windows
      const double wall_height = indoor ? rng->Uniform(2.5, 3.5) : rng->Uniform(3.0, 12.0);
      OrderedJson facade = Background(fmt::format("facade_{}", label), "facade", label, color);
      facade["size"] = {Metres(width), 0.5, Metres(wall_height)};
      facade["floors"] = std::max(1, static_cast<int>(wall_height / 3.0));
      facade["windows_per_floor"] = std::clamp(static_cast<int>(width / rng->Uniform(2.5, 5.0)), 1, 16);
      facade["translate"] = Array3(Vector3d(center_x, back_y, 0));
      objects.push_back(facade);
    } else if (style == 1) {  // a free-standing wall, often brick
      const double wall_height = indoor ? rng->Uniform(2.5, 3.5) : rng->Uniform(1.0, 3.0);
      OrderedJson wall = Background(fmt::format("wall_{}", label), "wall", label, color);
      wall["size"] = {Metres(width), 0.3, Metres(wall_height)};
      wall["translate"] = Array3(Vector3d(center_x, back_y + 0.15, 0));
      if (rng->Chance(0.6)) wall["texture"] = "brick";
      objects.push_back(wall);
    } else {  // a plain wall with a recess (a niche with a dark window at its back)
      const double wall_height = indoor ? rng->Uniform(2.5, 3.5) : rng->Uniform(2.0, 5.0);
      const double recess_width = rng->Uniform(1.0, 3.0), recess_depth = rng->Uniform(0.1, 0.4);
      const double recess_x = target.position.x() + rng->Uniform(-2.0, 2.0);
      const double left = recess_x - recess_width / 2, right = recess_x + recess_width / 2;
      auto slab = [&](const std::string& part, double xa, double xb, double y_front, double thickness) {
        OrderedJson box = Background(fmt::format("wall_{}/{}", label, part), "box", label, color);
        box["size"] = {Metres(xb - xa), Metres(thickness), Metres(wall_height)};
        box["translate"] = Array3(Vector3d((xa + xb) / 2, y_front + thickness / 2, wall_height / 2));
        objects.push_back(box);
      };
      slab("left", std::min(x0, left - 1), left, back_y, 0.3);
      slab("right", right, std::max(x1, right + 1), back_y, 0.3);
      slab("recess", left, right, back_y + recess_depth, 0.3);
      OrderedJson window = Background(fmt::format("wall_{}/window", label), "box", label, rng->Color());
      const double window_height = wall_height * rng->Uniform(0.3, 0.6);
      window["size"] = {Metres(recess_width * 0.7), 0.02, Metres(window_height)};
      window["translate"] = Array3(Vector3d(recess_x, back_y + recess_depth - 0.01, wall_height * 0.55));
      objects.push_back(window);
    }
    if (steps > 0) {
      const double steps_width = rng->Uniform(3.0, 8.0),
                   steps_x = target.position.x() + rng->Uniform(-1.5, 1.5);
      const int32_t steps_label = next_label++;
      const Rgb8 steps_color = rng->Color();
      for (int i = 0; i < steps; ++i) {
        OrderedJson step_box =
            Background(fmt::format("steps_{}/step{}", steps_label, i), "box", steps_label, steps_color);
        const double depth = (steps - i) * tread;
        step_box["size"] = {Metres(steps_width), Metres(depth), Metres(rise)};
        step_box["translate"] = Array3(Vector3d(steps_x, back_y - depth / 2, (i + 0.5) * rise));
        objects.push_back(step_box);
      }
    }
    if (indoor && rng->Chance(0.5)) {  // a side wall
      const bool right = rng->Chance(0.5);
      const double x = right ? tx1 + rng->Uniform(0.3, 3.0) + 0.1 : tx0 - rng->Uniform(0.3, 3.0) - 0.1;
      const double y0 = std::max(0.5, ty0 - 8.0), wall_height = rng->Uniform(2.5, 3.5);
      OrderedJson side = Background(fmt::format("wall_{}", next_label), "box", next_label, rng->Color());
      ++next_label;
      side["size"] = {0.2, Metres(back_y - y0), Metres(wall_height)};
      side["translate"] = Array3(Vector3d(x, (y0 + back_y) / 2, wall_height / 2));
      objects.push_back(side);
    }
    if (indoor && height < 2.4 && rng->Chance(0.5)) {  // a ceiling
      const double ceiling = rng->Uniform(std::max(2.5, height + 0.5), 3.5);
      OrderedJson plane =
          Background(fmt::format("ceiling_{}", next_label), "plane", next_label, rng->Color());
      ++next_label;
      plane["size"] = {60, 60};
      plane["translate"] = Array3(Vector3d(0, back_y - 20, ceiling));
      objects.push_back(plane);
    }
  }

  // Colour the target like its background (the wall behind it, or the ground) in a quarter of the scenes.
  if (rng->Chance(0.25)) {
    const OrderedJson& like = back && rng->Chance(0.6) ? wall_color : ground_color;
    const Rgb8 color(like[0].get<uint8_t>(), like[1].get<uint8_t>(), like[2].get<uint8_t>());
    for (Part& part : target.thing.parts) {
      if (part.main) part.color = color;
    }
  }
  target.label = next_label++;
  target.name = fmt::format("{}_{}", target.thing.kind, target.label);
  std::vector<Placed> placed = {target};

  // Neighbours: touching the target, beside it, behind it, or against the wall.
  const int neighbours = rng->Int(0, o.max_neighbours);
  for (int n = 0; n < neighbours; ++n) {
    Placed other;
    other.thing = random_scene::MakeThing(
        rng->Pick(indoor ? random_scene::IndoorKinds() : random_scene::StreetNeighbourKinds()), rng);
    const Thing& t = target.thing;
    const Thing& u = other.thing;
    const double mode = rng->Uniform(0, 1);
    other.yaw_deg = target.yaw_deg;
    Vector2d local;     // in the target's frame
    if (mode < 0.65) {  // touching (gap 0) or beside (gap 0.2..3 m), left or right
      const double gap = mode < 0.3 ? 0.0 : rng->Uniform(0.2, 3.0);
      const double dy = rng->Uniform(-0.3, 0.3) * std::min(t.max.y() - t.min.y(), u.max.y() - u.min.y());
      local = rng->Chance(0.5) ? Vector2d(t.max.x() - u.min.x() + gap, dy)
                               : Vector2d(t.min.x() - u.max.x() - gap, dy);
      other.position.head<2>() = target.ToWorld(local);
    } else if (mode < 0.8 || !back || steps > 0) {  // behind the target
      const double across = rng->Uniform(-1.0, 1.0), behind = rng->Uniform(0.3, 3.0);
      local = Vector2d(across, t.max.y() - u.min.y() + behind);
      other.position.head<2>() = target.ToWorld(local);
    } else {  // against the wall, facing the scanner
      other.yaw_deg = 0;
      other.position.head<2>() = Vector2d(target.position.x() + rng->Uniform(-3.0, 3.0), back_y - u.max.y());
    }
    double x0, x1, y0, y1;
    other.Bounds2(&x0, &x1, &y0, &y1);
    // Keep it standing on one level, before the wall and the steps, and clear of everything placed.
    if (kerb && y0 < kerb_y && y1 > kerb_y) continue;
    if (y1 > front_limit + 1e-6 || y0 < 0.5) continue;
    bool clear = true;
    for (const Placed& p : placed) clear = clear && !Overlap(p.Footprint(), other.Footprint());
    if (!clear) continue;
    other.position.z() = base_z(y0, y1);
    other.label = next_label++;
    other.name = fmt::format("{}_{}", other.thing.kind, other.label);
    placed.push_back(other);
  }
  for (const Placed& p : placed) Emit(p, &objects);

  Draft draft;
  draft.target_label = target.label;
  draft.target_kind = target.thing.kind;
  draft.target_distance_m = distance;
  OrderedJson& root = draft.root;
  root["name"] = fmt::format("random_{}", seed);
  root["description"] = fmt::format(
      "Random {} scene (scanner/random_scene.h), seed {}: the target is {} (label {}) at {:.1f} m.",
      indoor ? "indoor" : "street", seed, target.name, target.label, distance);
  OrderedJson scanner;
  scanner["position"] = Array3(Vector3d(0, 0, height));
  scanner["azimuth_deg"] = {Degrees(window_az0), Degrees(window_az0 + az_span)};
  scanner["elevation_deg"] = {Degrees(window_el0), Degrees(window_el1)};
  scanner["columns"] = o.columns;
  scanner["rows"] = o.rows;
  scanner["max_range"] = std::max(100.0, std::ceil(2 * ground_size));
  scanner["los_noise_sigma"] = o.los_noise_sigma_m;
  scanner["orthogonal_noise_sigma"] = o.orthogonal_noise_sigma_m;
  scanner["seed"] = seed % (uint64_t{1} << 31);
  root["scanner"] = scanner;
  root["target_label"] = target.label;
  root["objects"] = objects;
  return draft;
}

}  // namespace

void RandomSceneOptions::Check() const {
  CheckOption(
      columns >= 64 && rows >= 64 && int64_t{columns} * rows <= (int64_t{1} << 24),
      fmt::format("random scene: columns and rows must be >= 64 (and their product <= 2^24), got {} x {}",
                  columns, rows));
  CheckOption(min_distance_m > 0 && max_distance_m >= min_distance_m && max_distance_m <= 1000,
              "random scene: distances must satisfy 0 < min <= max <= 1000 m");
  CheckOption(
      min_scanner_height_m > 0 && max_scanner_height_m >= min_scanner_height_m && max_scanner_height_m <= 100,
      "random scene: scanner heights must satisfy 0 < min <= max <= 100 m");
  CheckOption(min_target_share > 0 && max_target_share >= min_target_share && max_target_share <= 0.9,
              "random scene: target shares must satisfy 0 < min <= max <= 0.9");
  CheckOption(max_neighbours >= 0 && max_neighbours <= 16, "random scene: max_neighbours must be in [0, 16]");
  CheckOption(indoor_share >= 0 && indoor_share <= 1, "random scene: indoor_share must be in [0, 1]");
  CheckOption(los_noise_sigma_m >= 0 && orthogonal_noise_sigma_m >= 0,
              "random scene: noise sigmas must be >= 0");
  CheckOption(min_visible_cells >= 1 && min_target_cells >= 1 &&
                  int64_t{min_target_cells} <= int64_t{columns} * rows / 20,
              "random scene: min_visible_cells and min_target_cells must be >= 1, min_target_cells at most a "
              "twentieth of the window");
}

std::string RandomSceneJson(uint64_t seed, const RandomSceneOptions& options) {
  options.Check();
  Rng rng(seed);
  constexpr int kAttempts = 64;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    Draft draft = Draw(&rng, options, seed);
    // Scan once: leave out what the window does not show, draw again when the target shows too little.
    const std::string what = fmt::format("random scene {}", seed);
    const SceneDescription scene = ParseScene(draft.root.dump(), what, "");
    const Scan scan = SynthesizeScan(scene);
    std::map<int32_t, int64_t> cells;
    for (int y = 0; y < scan.rows; ++y) {
      for (int x = 0; x < scan.cols; ++x) {
        if (scan.valid.at<uint8_t>(y, x)) ++cells[scan.label.at<int32_t>(y, x)];
      }
    }
    if (cells[draft.target_label] < options.min_target_cells) continue;
    OrderedJson& objects = draft.root["objects"];
    OrderedJson kept = OrderedJson::array();
    for (const OrderedJson& object : objects) {
      if (cells[object["label"].get<int32_t>()] >= options.min_visible_cells) kept.push_back(object);
    }
    objects = kept;
    return draft.root.dump(1);
  }
  // With the default options the target spans 20-45 % of the window and redraws are rare; options asking for
  // more target cells than such a window holds end here.
  throw OptionsError(fmt::format(
      "random scene {}: no draw in {} gave the target {} returns (min_target_cells) in a {} x {} window",
      seed, kAttempts, options.min_target_cells, options.columns, options.rows));
}

SceneDescription RandomScene(uint64_t seed, const RandomSceneOptions& options) {
  return ParseScene(RandomSceneJson(seed, options), fmt::format("random scene {}", seed), "");
}

}  // namespace lidarshop
