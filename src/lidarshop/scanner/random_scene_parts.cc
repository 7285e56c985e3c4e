#include "lidarshop/scanner/random_scene_parts.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/error.h"

namespace lidarshop::random_scene {
namespace {

using Eigen::Vector3d;
using OrderedJson = nlohmann::ordered_json;

Part Box(const std::string& name, const Vector3d& size, const Vector3d& center, Rgb8 color,
         bool main = true) {
  Part part{name, "box", OrderedJson::object(), center, color, main};
  part.parameters["size"] = {size.x(), size.y(), size.z()};
  return part;
}

Part Round(const std::string& name, const std::string& primitive, double radius, double height,
           const Vector3d& center, Rgb8 color, bool main = true) {
  Part part{name, primitive, OrderedJson::object(), center, color, main};
  part.parameters["radius"] = radius;
  if (primitive != "sphere") part.parameters["height"] = height;
  part.parameters["segments"] = primitive == "sphere" ? 32 : 24;
  return part;
}

// The part's bounding box in the object's frame.
void PartBounds(const Part& part, Vector3d* lo, Vector3d* hi) {
  Vector3d half;
  if (part.primitive == "box") {
    const auto& s = part.parameters["size"];
    half = Vector3d(s[0].get<double>(), s[1].get<double>(), s[2].get<double>()) / 2;
  } else if (part.primitive == "sphere") {
    half.setConstant(part.parameters["radius"].get<double>());
  } else if (part.primitive == "cylinder" || part.primitive == "cone") {
    const double r = part.parameters["radius"].get<double>();
    half = Vector3d(r, r, part.parameters["height"].get<double>() / 2);
  } else {  // composite primitives: from their mesh
    const TriangleMesh mesh = MakePrimitive(part.primitive, part.parameters.dump());
    LIDARSHOP_CHECK(!mesh.vertices.empty());
    Vector3d mesh_lo = Vector3d::Constant(1e9), mesh_hi = Vector3d::Constant(-1e9);
    for (const Eigen::Vector3f& v : mesh.vertices) {
      mesh_lo = mesh_lo.cwiseMin(v.cast<double>());
      mesh_hi = mesh_hi.cwiseMax(v.cast<double>());
    }
    *lo = mesh_lo + part.center;
    *hi = mesh_hi + part.center;
    return;
  }
  *lo = part.center - half;
  *hi = part.center + half;
}

Rgb8 Wood(Rng* rng) {
  const int r = rng->Int(90, 150), g = rng->Int(60, 100), b = rng->Int(35, 60);
  return Rgb8(static_cast<uint8_t>(r), static_cast<uint8_t>(g), static_cast<uint8_t>(b));
}
Rgb8 Metal(Rng* rng) {
  const uint8_t v = static_cast<uint8_t>(rng->Int(40, 140));
  return Rgb8(v, v, static_cast<uint8_t>(std::min(255, v + 6)));
}
Rgb8 Skin(Rng* rng) {
  const double t = rng->Uniform(0, 1);
  return Rgb8(static_cast<uint8_t>(90 + 140 * t), static_cast<uint8_t>(60 + 110 * t),
              static_cast<uint8_t>(45 + 90 * t));
}

Thing PostBox(Rng* rng) {  // a mailbox-like box on a post, overhanging the post towards the scanner
  const double pw = rng->Uniform(0.06, 0.12), ph = rng->Uniform(0.8, 1.3);
  const double bw = rng->Uniform(0.3, 0.6), bd = rng->Uniform(0.3, 0.55), bh = rng->Uniform(0.2, 0.4);
  const Vector3d box(bw, bd, bh);
  const double overhang = rng->Uniform(0.1, 0.25);
  const double front = -pw / 2 - overhang;
  const Rgb8 post = rng->Chance(0.5) ? Wood(rng) : Metal(rng);
  return {"post_box",
          {Box("post", Vector3d(pw, pw, ph), Vector3d(0, 0, ph / 2), post, false),
           Box("box", box, Vector3d(0, front + box.y() / 2, ph + box.z() / 2), rng->Color())}};
}

Thing Sign(Rng* rng) {
  const double r = rng->Uniform(0.03, 0.05), height = rng->Uniform(2.0, 2.6);
  const double plate_w = rng->Uniform(0.4, 0.8), plate_h = rng->Uniform(0.3, 0.6),
               drop = rng->Uniform(0, 0.1);
  const Vector3d plate(plate_w, 0.03, plate_h);
  const Rgb8 post = Metal(rng), color = rng->Color();
  return {"sign",
          {Round("post", "cylinder", r, height, Vector3d(0, 0, height / 2), post, false),
           Box("plate", plate, Vector3d(0, -r - 0.015, height - plate.z() / 2 - drop), color)}};
}

Thing Table(Rng* rng, bool chair) {
  const double w = chair ? rng->Uniform(0.4, 0.5) : rng->Uniform(0.8, 1.6);
  const double d = chair ? w : rng->Uniform(0.6, 1.0);
  const double t = rng->Uniform(0.03, 0.06), h = chair ? rng->Uniform(0.42, 0.48) : rng->Uniform(0.7, 0.8);
  const double leg = rng->Uniform(0.03, 0.07), inset = rng->Uniform(0.0, 0.08);
  const Rgb8 top = rng->Color(), legs = rng->Chance(0.5) ? top : rng->Color();
  Thing thing{chair ? "chair" : "table", {Box("top", Vector3d(w, d, t), Vector3d(0, 0, h - t / 2), top)}};
  for (int i = 0; i < 4; ++i) {
    const double x = (i % 2 ? 1 : -1) * (w / 2 - leg / 2 - inset),
                 y = (i / 2 ? 1 : -1) * (d / 2 - leg / 2 - inset);
    thing.parts.push_back(Box(fmt::format("leg{}", i), Vector3d(leg, leg, h - t), Vector3d(x, y, (h - t) / 2),
                              legs, legs == top));
  }
  if (chair) {
    const double back = rng->Uniform(0.35, 0.5);
    thing.parts.push_back(Box("back", Vector3d(w, 0.04, back), Vector3d(0, d / 2 - 0.02, h + back / 2), top));
  }
  return thing;
}

Thing Bench(Rng* rng) {
  const double length = rng->Uniform(1.2, 2.0), seat_h = rng->Uniform(0.42, 0.48);
  const Rgb8 wood = rng->Chance(0.7) ? Wood(rng) : rng->Color(), metal = Metal(rng);
  Thing thing{"bench",
              {Box("seat", Vector3d(length, 0.45, 0.05), Vector3d(0, 0, seat_h), wood),
               Box("back", Vector3d(length, 0.05, 0.42), Vector3d(0, 0.2, seat_h + 0.235), wood)}};
  for (int side : {-1, 1}) {
    const double x = side * (length / 2 - 0.1);
    thing.parts.push_back(Box(side < 0 ? "leg_left" : "leg_right", Vector3d(0.06, 0.45, seat_h - 0.025),
                              Vector3d(x, 0, (seat_h - 0.025) / 2), metal, false));
  }
  return thing;
}

Thing Bin(Rng* rng) {
  const double r = rng->Uniform(0.2, 0.35), h = rng->Uniform(0.6, 1.0);
  const Rgb8 body = rng->Color();
  return {"bin",
          {Round("body", "cylinder", r, h, Vector3d(0, 0, h / 2), body),
           Round("lid", "cylinder", r + 0.02, 0.05, Vector3d(0, 0, h + 0.025),
                 rng->Chance(0.5) ? body : rng->Color())}};
}

Thing Crate(Rng* rng) {
  const double sx = rng->Uniform(0.3, 1.0), sy = rng->Uniform(0.3, 1.0), sz = rng->Uniform(0.3, 1.0);
  const Vector3d size(sx, sy, sz);
  Thing thing{"crate", {Box("box", size, Vector3d(0, 0, size.z() / 2), rng->Color())}};
  if (rng->Chance(0.4)) {  // a second, smaller box on top, of another colour
    const double fx = rng->Uniform(0.4, 0.9), fy = rng->Uniform(0.4, 0.9), tz = rng->Uniform(0.15, 0.4);
    const Vector3d top(size.x() * fx, size.y() * fy, tz);
    thing.parts.push_back(Box("top", top, Vector3d(0, 0, size.z() + top.z() / 2), rng->Color()));
  }
  return thing;
}

Thing Person(Rng* rng) {
  const double h = rng->Uniform(1.5, 1.9), leg = 0.47 * h, torso = 0.3 * h, head = 0.065 * h;
  const Rgb8 trousers = rng->Color(), shirt = rng->Color(), skin = Skin(rng);
  Thing thing{"person",
              {Box("torso", Vector3d(0.4, 0.22, torso), Vector3d(0, 0, leg + torso / 2), shirt),
               Round("head", "sphere", head, 0, Vector3d(0, 0, leg + torso + 0.9 * head), skin, false)}};
  for (int side : {-1, 1}) {
    thing.parts.push_back(Box(side < 0 ? "leg_left" : "leg_right", Vector3d(0.13, 0.15, leg),
                              Vector3d(side * 0.09, 0, leg / 2), trousers, false));
    const double arm = 0.95 * torso;
    thing.parts.push_back(Box(side < 0 ? "arm_left" : "arm_right", Vector3d(0.08, 0.1, arm),
                              Vector3d(side * 0.24, 0, leg + torso - arm / 2), shirt));
  }
  return thing;
}

Thing Ball(Rng* rng) {
  const double r = rng->Uniform(0.15, 0.5);
  return {"ball", {Round("ball", "sphere", r, 0, Vector3d(0, 0, r), rng->Color())}};
}

Thing TrafficCone(Rng* rng) {
  const double r = rng->Uniform(0.12, 0.2), h = rng->Uniform(0.45, 0.75);
  const Rgb8 color = rng->Chance(0.7) ? Rgb8(230, static_cast<uint8_t>(rng->Int(70, 110)), 20) : rng->Color();
  return {"cone",
          {Box("base", Vector3d(2 * r + 0.08, 2 * r + 0.08, 0.03), Vector3d(0, 0, 0.015), Metal(rng), false),
           Round("cone", "cone", r, h, Vector3d(0, 0, 0.03 + h / 2), color)}};
}

Thing Bollard(Rng* rng) {
  const double r = rng->Uniform(0.06, 0.12), h = rng->Uniform(0.7, 1.1);
  const Rgb8 color = rng->Color();
  return {"bollard",
          {Round("body", "cylinder", r, h, Vector3d(0, 0, h / 2), color),
           Round("cap", "sphere", r, 0, Vector3d(0, 0, h), rng->Chance(0.5) ? color : rng->Color())}};
}

Thing Composite(const std::string& kind, const std::string& primitive, OrderedJson parameters, Rgb8 color) {
  Part part{kind, primitive, std::move(parameters), Vector3d::Zero(), color, true};
  return {kind, {part}};
}

}  // namespace

Rgb8 Rng::Color() {
  // HSV to RGB by hand: hue in [0, 6), saturation 0..0.9 (a quarter of the colours grey), value 0.15..0.95.
  const double hue = Uniform(0, 6), saturation = Chance(0.25) ? Uniform(0, 0.12) : Uniform(0.25, 0.9);
  const double value = Uniform(0.15, 0.95);
  const int sector = std::min(5, static_cast<int>(hue));
  const double f = hue - sector, p = value * (1 - saturation), q = value * (1 - saturation * f),
               t = value * (1 - saturation * (1 - f));
  const double rgb[6][3] = {{value, t, p}, {q, value, p}, {p, value, t},
                            {p, q, value}, {t, p, value}, {value, p, q}};
  auto byte = [](double c) { return static_cast<uint8_t>(std::clamp(std::lround(255 * c), 0L, 255L)); };
  return Rgb8(byte(rgb[sector][0]), byte(rgb[sector][1]), byte(rgb[sector][2]));
}

const std::vector<std::string>& StreetKinds() {
  static const std::vector<std::string> kinds = {"post_box", "sign",    "table",  "bench",   "bin",
                                                 "crate",    "ball",    "cone",   "bollard", "car",
                                                 "person",   "cabinet", "mailbox"};
  return kinds;
}
const std::vector<std::string>& IndoorKinds() {
  static const std::vector<std::string> kinds = {"table", "chair", "person",  "crate",
                                                 "bin",   "ball",  "post_box"};
  return kinds;
}
const std::vector<std::string>& StreetNeighbourKinds() {
  static const std::vector<std::string> kinds = [] {
    std::vector<std::string> k = StreetKinds();
    k.push_back("lamp_post");
    return k;
  }();
  return kinds;
}

Thing MakeThing(const std::string& kind, Rng* rng) {
  Thing thing;
  if (kind == "post_box")
    thing = PostBox(rng);
  else if (kind == "sign")
    thing = Sign(rng);
  else if (kind == "table")
    thing = Table(rng, false);
  else if (kind == "chair")
    thing = Table(rng, true);
  else if (kind == "bench")
    thing = Bench(rng);
  else if (kind == "bin")
    thing = Bin(rng);
  else if (kind == "crate")
    thing = Crate(rng);
  else if (kind == "ball")
    thing = Ball(rng);
  else if (kind == "cone")
    thing = TrafficCone(rng);
  else if (kind == "bollard")
    thing = Bollard(rng);
  else if (kind == "person")
    thing = Person(rng);
  else if (kind == "car") {
    const std::string style = rng->Pick<std::string>({"sedan", "hatchback", "van"});
    thing = Composite("car", "car", {{"style", style}}, rng->Color());
  } else if (kind == "cabinet") {
    thing = Composite("cabinet", "electric_box", OrderedJson::object(), rng->Color());
  } else if (kind == "mailbox") {
    thing = Composite("mailbox", "mailbox", OrderedJson::object(), rng->Color());
  } else if (kind == "lamp_post") {
    const double height = rng->Uniform(4.0, 7.0);
    thing = Composite("lamp_post", "lamp_post", {{"height", height}}, Metal(rng));
  } else {
    throw std::logic_error("random scene: unknown kind of object '" + kind + "'");
  }
  thing.min = Vector3d::Constant(1e9);
  thing.max = Vector3d::Constant(-1e9);
  for (const Part& part : thing.parts) {
    Vector3d lo, hi;
    PartBounds(part, &lo, &hi);
    thing.min = thing.min.cwiseMin(lo);
    thing.max = thing.max.cwiseMax(hi);
  }
  return thing;
}

}  // namespace lidarshop::random_scene
