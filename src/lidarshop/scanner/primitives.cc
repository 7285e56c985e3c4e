#include "lidarshop/scanner/primitives.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::Vector3f;

// Appends vertices with normals and triangles with (optional) colours.
class MeshBuilder {
 public:
  explicit MeshBuilder(bool with_colors) : with_colors_(with_colors) {}

  int AddVertex(const Vector3d& position, const Vector3d& normal) {
    mesh_.vertices.push_back(position.cast<float>());
    mesh_.vertex_normals.push_back(normal.normalized().cast<float>());
    return static_cast<int>(mesh_.vertices.size()) - 1;
  }
  void AddTriangle(int a, int b, int c, Rgb8 color) {
    mesh_.triangles.emplace_back(a, b, c);
    if (with_colors_) mesh_.triangle_colors.push_back(color);
  }
  // A flat convex polygon (corners in order, either winding), oriented so that its
  // normal points along `outward`.
  void AddPolygon(std::vector<Vector3d> corners, const Vector3d& outward, Rgb8 color) {
    if (corners.size() < 3) return;
    Vector3d normal = Vector3d::Zero();
    for (size_t i = 1; i + 1 < corners.size(); ++i) {
      normal += (corners[i] - corners[0]).cross(corners[i + 1] - corners[0]);
    }
    if (normal.dot(outward) < 0) {
      std::reverse(corners.begin(), corners.end());
      normal = -normal;
    }
    if (normal.norm() == 0) return;
    std::vector<int> ids;
    for (const auto& corner : corners) ids.push_back(AddVertex(corner, normal));
    for (size_t i = 1; i + 1 < ids.size(); ++i) AddTriangle(ids[0], ids[i], ids[i + 1], color);
  }
  void AddQuad(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d,
               const Vector3d& outward, Rgb8 color) {
    AddPolygon({a, b, c, d}, outward, color);
  }
  // Axis-aligned box centred at `center`; `skip_bottom` leaves out the face at -z (it stands on something).
  void AddBox(const Vector3d& center, const Vector3d& size, Rgb8 color, bool skip_bottom = false) {
    const Vector3d h = size / 2;
    for (int axis = 0; axis < 3; ++axis) {
      for (int sign : {-1, 1}) {
        if (skip_bottom && axis == 2 && sign < 0) continue;
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        Vector3d n = Vector3d::Zero();
        n[axis] = sign;
        std::vector<Vector3d> corners;
        for (auto [su, sv] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
          Vector3d p = center;
          p[axis] += sign * h[axis];
          p[u] += su * h[u];
          p[v] += sv * h[v];
          corners.push_back(p);
        }
        AddPolygon(corners, n, color);
      }
    }
  }
  // A frustum around `axis` from `base` (radius r0) to base + height * axis (radius r1), angles in
  // [angle0, angle1] measured from `reference` (perpendicular to axis) towards axis x reference. Smooth side
  // normals; flat caps when `caps` (and the radius is > 0).
  void AddFrustum(const Vector3d& base, Vector3d axis, Vector3d reference, double r0, double r1,
                  double height, int segments, Rgb8 side_color, bool caps, Rgb8 cap_color,
                  double angle0 = 0.0, double angle1 = 2 * M_PI) {
    axis.normalize();
    reference = (reference - reference.dot(axis) * axis).normalized();
    const Vector3d binormal = axis.cross(reference);
    const Vector3d top = base + height * axis;
    const bool full = angle1 - angle0 >= 2 * M_PI - 1e-9;
    const int ring = full ? segments : segments + 1;
    std::vector<Vector3d> radial(ring);
    for (int i = 0; i < ring; ++i) {
      const double angle = angle0 + (angle1 - angle0) * i / segments;
      radial[i] = std::cos(angle) * reference + std::sin(angle) * binormal;
    }
    // Side: normal of the slanted surface = radial * height + axis * (r0 - r1).
    std::vector<int> bottom_ids(ring), top_ids(ring);
    for (int i = 0; i < ring; ++i) {
      const Vector3d normal = radial[i] * height + axis * (r0 - r1);
      bottom_ids[i] = AddVertex(base + r0 * radial[i], normal);
      top_ids[i] = AddVertex(top + r1 * radial[i], normal);
    }
    for (int i = 0; i < segments; ++i) {
      const int j = full ? (i + 1) % segments : i + 1;
      if (r0 > 0) AddTriangle(bottom_ids[i], bottom_ids[j], top_ids[j], side_color);
      if (r1 > 0) AddTriangle(bottom_ids[i], top_ids[j], top_ids[i], side_color);
    }
    if (!caps) return;
    for (int end = 0; end < 2; ++end) {
      const double radius = end == 0 ? r0 : r1;
      if (radius <= 0) continue;
      const Vector3d center = end == 0 ? base : top;
      const Vector3d normal = end == 0 ? Vector3d(-axis) : axis;
      std::vector<Vector3d> corners;
      if (!full) corners.push_back(center);
      for (int i = 0; i < ring; ++i) corners.push_back(center + radius * radial[i]);
      AddPolygon(corners, normal, cap_color);
    }
  }
  // Extrudes a convex polygon given in the (y, z) plane along x from x0 to x1. `side_color(i)` colours the
  // face between profile corners i and i+1; the two caps get `cap_color`.
  template <typename SideColor>
  void AddExtrudedProfile(const std::vector<Vector2d>& profile, double x0, double x1, SideColor side_color,
                          Rgb8 cap_color) {
    Vector2d centroid = Vector2d::Zero();
    for (const auto& p : profile) centroid += p;
    centroid /= static_cast<double>(profile.size());
    const int n = static_cast<int>(profile.size());
    for (int i = 0; i < n; ++i) {
      const Vector2d& p = profile[i];
      const Vector2d& q = profile[(i + 1) % n];
      const Vector2d mid = (p + q) / 2 - centroid;
      AddQuad(Vector3d(x0, p.x(), p.y()), Vector3d(x1, p.x(), p.y()), Vector3d(x1, q.x(), q.y()),
              Vector3d(x0, q.x(), q.y()), Vector3d(0, mid.x(), mid.y()), side_color(i));
    }
    for (double x : {x0, x1}) {
      std::vector<Vector3d> corners;
      for (const auto& p : profile) corners.emplace_back(x, p.x(), p.y());
      AddPolygon(corners, Vector3d(x < (x0 + x1) / 2 ? -1 : 1, 0, 0), cap_color);
    }
  }

  TriangleMesh Take() { return std::move(mesh_); }

 private:
  bool with_colors_;
  TriangleMesh mesh_;
};

}  // namespace

TriangleMesh MakePlaneMesh(const Vector2d& size) {
  MeshBuilder builder(false);
  const double hx = size.x() / 2, hy = size.y() / 2;
  builder.AddQuad(Vector3d(-hx, -hy, 0), Vector3d(hx, -hy, 0), Vector3d(hx, hy, 0), Vector3d(-hx, hy, 0),
                  Vector3d::UnitZ(), Rgb8::Zero());
  return builder.Take();
}

TriangleMesh MakeBoxMesh(const Vector3d& size) {
  MeshBuilder builder(false);
  builder.AddBox(Vector3d::Zero(), size, Rgb8::Zero());
  return builder.Take();
}

TriangleMesh MakeSphereMesh(double radius, int segments) {
  segments = std::max(segments, 3);
  const int rings = std::max(2, segments / 2);
  TriangleMesh mesh;
  for (int ring = 0; ring <= rings; ++ring) {
    const double polar = M_PI * ring / rings;
    for (int i = 0; i <= segments; ++i) {
      const double azimuth = 2 * M_PI * i / segments;
      const Vector3d normal(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                            std::cos(polar));
      mesh.vertices.push_back((radius * normal).cast<float>());
      mesh.vertex_normals.push_back(normal.cast<float>());
    }
  }
  const int stride = segments + 1;
  for (int ring = 0; ring < rings; ++ring) {
    for (int i = 0; i < segments; ++i) {
      const int a = ring * stride + i, b = a + 1, c = a + stride, d = c + 1;
      // From outside, with z up and azimuth counter-clockwise: a (upper) -> c (lower) -> d is
      // counter-clockwise.
      if (ring > 0) mesh.triangles.emplace_back(a, c, b);
      if (ring < rings - 1) mesh.triangles.emplace_back(b, c, d);
    }
  }
  return mesh;
}

TriangleMesh MakeCylinderMesh(double radius, double height, int segments) {
  MeshBuilder builder(false);
  builder.AddFrustum(Vector3d(0, 0, -height / 2), Vector3d::UnitZ(), Vector3d::UnitX(), radius, radius,
                     height, std::max(segments, 3), Rgb8::Zero(), true, Rgb8::Zero());
  return builder.Take();
}

TriangleMesh MakeConeMesh(double radius, double height, int segments) {
  MeshBuilder builder(false);
  builder.AddFrustum(Vector3d(0, 0, -height / 2), Vector3d::UnitZ(), Vector3d::UnitX(), radius, 0.0, height,
                     std::max(segments, 3), Rgb8::Zero(), true, Rgb8::Zero());
  return builder.Take();
}

CarStyle ParseCarStyle(const std::string& style, const std::string& what) {
  if (style == "suv") return CarStyle::kVan;  // an older name scene files may use
  try {
    return ParseEnum<CarStyle>(style);
  } catch (const OptionsError& error) {
    ThrowInputError(what, "", "style", error.what());
  }
}

void CarMeshOptions::Check() const { Validate(*this); }

TriangleMesh MakeCarMesh(const CarMeshOptions& options) {
  options.Check();
  struct Shape {
    double length, width, wheel_radius, wheelbase;
    std::vector<Vector2d> body;   // (y, z), bonnet at -y
    std::vector<Vector2d> cabin;  // (y, z): windscreen base, rear base, rear roof, front roof
  };
  Shape shape{};
  switch (options.style) {
    case CarStyle::kSedan:
      shape = {4.6,
               1.8,
               0.32,
               2.7,
               {{-2.3, 0.30},
                {-2.22, 0.18},
                {2.22, 0.18},
                {2.3, 0.32},
                {2.3, 0.85},
                {2.1, 0.97},
                {-2.05, 0.9},
                {-2.3, 0.78}},
               {{-0.95, 0.92}, {1.35, 0.95}, {0.85, 1.45}, {-0.2, 1.45}}};
      break;
    case CarStyle::kHatchback:
      shape = {
          4.0,
          1.75,
          0.31,
          2.5,
          {{-2.0, 0.30}, {-1.93, 0.18}, {1.93, 0.18}, {2.0, 0.32}, {2.0, 0.95}, {-1.8, 0.9}, {-2.0, 0.78}},
          {{-0.7, 0.92}, {1.98, 0.95}, {1.82, 1.5}, {0.0, 1.5}}};
      break;
    case CarStyle::kVan:
      shape = {4.9,
               1.95,
               0.36,
               3.0,
               {{-2.45, 0.36},
                {-2.37, 0.22},
                {2.37, 0.22},
                {2.45, 0.36},
                {2.45, 1.05},
                {-2.2, 1.05},
                {-2.45, 0.92}},
               {{-1.25, 1.05}, {2.45, 1.05}, {2.42, 1.95}, {-0.55, 1.95}}};
      break;
  }
  const Rgb8 paint = options.paint;
  const Rgb8 glass(38, 46, 56), tyre(28, 28, 30), rim(165, 168, 172), trim(35, 35, 38);
  const Rgb8 head_light(235, 232, 210), tail_light(170, 20, 24);
  MeshBuilder builder(true);
  const double w = shape.width;
  builder.AddExtrudedProfile(
      shape.body, -w / 2, w / 2, [&](int) { return paint; }, paint);
  // The glass house: windscreen (face 3), roof (face 2) painted, rear window (face 1), sides glass.
  builder.AddExtrudedProfile(
      shape.cabin, -0.43 * w, 0.43 * w,
      [&](int face) { return face == 2   ? paint
                             : face == 0 ? paint
                                         : glass; }, glass);
  // Bumpers and lights.
  const double half_length = shape.length / 2;
  builder.AddBox(Vector3d(0, -half_length - 0.03, 0.34), Vector3d(w * 0.96, 0.1, 0.18), trim);
  builder.AddBox(Vector3d(0, half_length + 0.03, 0.36), Vector3d(w * 0.96, 0.1, 0.18), trim);
  const double light_z = options.style == CarStyle::kVan ? 0.85 : 0.7;
  for (int side : {-1, 1}) {
    builder.AddBox(Vector3d(side * 0.34 * w, -half_length - 0.01, light_z), Vector3d(0.32, 0.06, 0.12),
                   head_light);
    builder.AddBox(Vector3d(side * 0.36 * w, half_length + 0.01, light_z + 0.05), Vector3d(0.26, 0.06, 0.12),
                   tail_light);
  }
  // Wheels: axis along x, the outer disc shows the rim.
  const double r = shape.wheel_radius, tyre_width = 0.22;
  for (int side : {-1, 1}) {
    for (int end : {-1, 1}) {
      const Vector3d inner(side * (w / 2 - tyre_width + 0.02), end * shape.wheelbase / 2, r);
      builder.AddFrustum(inner, Vector3d(side, 0, 0), Vector3d::UnitZ(), r, r, tyre_width,
                         options.wheel_segments, tyre, true, rim);
    }
  }
  return SubdivideMesh(builder.Take(), options.subdivisions);
}

TriangleMesh MakeLampPostMesh(double height, int segments) {
  const Rgb8 metal(72, 84, 80), lamp(225, 225, 205);
  MeshBuilder builder(true);
  builder.AddFrustum(Vector3d::Zero(), Vector3d::UnitZ(), Vector3d::UnitX(), 0.18, 0.14, 0.6, segments, metal,
                     true, metal);
  builder.AddFrustum(Vector3d(0, 0, 0.6), Vector3d::UnitZ(), Vector3d::UnitX(), 0.09, 0.06, height - 0.6,
                     segments, metal, true, metal);
  const double arm = 1.4;
  builder.AddBox(Vector3d(0, -arm / 2, height - 0.12), Vector3d(0.07, arm, 0.07), metal);
  builder.AddBox(Vector3d(0, -arm, height - 0.2), Vector3d(0.32, 0.6, 0.12), metal);
  builder.AddBox(Vector3d(0, -arm, height - 0.275), Vector3d(0.28, 0.52, 0.03), lamp);
  return builder.Take();
}

TriangleMesh MakeElectricBoxMesh(Rgb8 paint) {
  const Rgb8 concrete(150, 148, 140), dark(40, 42, 40), handle(180, 180, 176), sign(235, 200, 30);
  MeshBuilder builder(true);
  builder.AddBox(Vector3d(0, 0, 0.075), Vector3d(1.0, 0.55, 0.15), concrete, true);
  builder.AddBox(Vector3d(0, 0, 0.15 + 0.6), Vector3d(0.9, 0.45, 1.2), paint);
  builder.AddBox(Vector3d(0, 0, 1.35 + 0.03), Vector3d(0.98, 0.53, 0.06), paint);
  const double front = -0.225;
  builder.AddBox(Vector3d(0, front - 0.004, 0.75), Vector3d(0.012, 0.008, 1.1),
                 dark);  // seam between the doors
  for (int side : {-1, 1}) {
    builder.AddBox(Vector3d(side * 0.07, front - 0.02, 0.8), Vector3d(0.03, 0.04, 0.14), handle);
  }
  builder.AddBox(Vector3d(-0.25, front - 0.003, 1.12), Vector3d(0.16, 0.006, 0.14), sign);
  return builder.Take();
}

TriangleMesh MakeMailboxMesh(Rgb8 paint, int segments) {
  const Rgb8 wood(112, 82, 52), flag(200, 30, 30);
  MeshBuilder builder(true);
  builder.AddBox(Vector3d(0, 0.08, 0.5), Vector3d(0.1, 0.1, 1.0), wood, true);
  builder.AddBox(Vector3d(0, 0.08, 1.02), Vector3d(0.16, 0.4, 0.04), wood);
  const double width = 0.23, length = 0.5, z0 = 1.04, box_height = 0.12;
  builder.AddBox(Vector3d(0, 0, z0 + box_height / 2), Vector3d(width, length, box_height), paint);
  // The rounded top: a half cylinder along y with flat end caps.
  builder.AddFrustum(Vector3d(0, -length / 2, z0 + box_height), Vector3d::UnitY(), Vector3d::UnitX(),
                     width / 2, width / 2, length, segments, paint, true, paint, 0.0, M_PI);
  builder.AddBox(Vector3d(width / 2 + 0.008, 0.12, z0 + 0.12), Vector3d(0.012, 0.03, 0.2), flag);
  builder.AddBox(Vector3d(width / 2 + 0.008, 0.17, z0 + 0.2), Vector3d(0.012, 0.12, 0.06), flag);
  return builder.Take();
}

void FacadeMeshOptions::Check() const { Validate(*this); }

TriangleMesh MakeFacadeMesh(const FacadeMeshOptions& options) {
  options.Check();
  const double w = options.width, h = options.height, d = options.depth, inset = 0.15;
  const Rgb8 door_color(92, 62, 42), frame(235, 235, 230);
  struct Opening {
    double x0, x1, z0, z1;
    bool door;
  };
  std::vector<Opening> openings;
  const double floor_height = h / options.floors;
  const double cell = w / options.windows_per_floor;
  const double window_width = std::min(1.5, 0.55 * cell), window_height = std::min(1.7, 0.5 * floor_height);
  const int door_column = options.windows_per_floor / 2;
  for (int floor = 0; floor < options.floors; ++floor) {
    for (int i = 0; i < options.windows_per_floor; ++i) {
      const double cx = -w / 2 + (i + 0.5) * cell;
      if (floor == 0 && i == door_column) {
        const double door_width = std::min(1.3, 0.7 * cell);
        openings.push_back(
            {cx - door_width / 2, cx + door_width / 2, 0.0, std::min(2.3, 0.85 * floor_height), true});
        continue;
      }
      const double z0 = floor * floor_height + 0.35 * floor_height;
      openings.push_back({cx - window_width / 2, cx + window_width / 2, z0, z0 + window_height, false});
    }
  }
  MeshBuilder builder(true);
  // Front face (y = 0, normal -y) with holes: a grid over every opening edge, cells outside openings kept.
  std::vector<double> xs = {-w / 2, w / 2}, zs = {0.0, h};
  for (const auto& o : openings) {
    xs.insert(xs.end(), {o.x0, o.x1});
    zs.insert(zs.end(), {o.z0, o.z1});
  }
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  std::sort(zs.begin(), zs.end());
  zs.erase(std::unique(zs.begin(), zs.end()), zs.end());
  // Each opening marks the grid cells it spans (found by binary search): a facade of 100 floors of 150
  // windows must not test every cell against every opening (minutes).
  const size_t grid_columns = xs.size() - 1;
  std::vector<char> open_cell(grid_columns * (zs.size() - 1), 0);
  auto grid_index = [](const std::vector<double>& edges, double value) {
    return static_cast<size_t>(std::lower_bound(edges.begin(), edges.end(), value) - edges.begin());
  };
  for (const auto& o : openings) {
    for (size_t j = grid_index(zs, o.z0); j < grid_index(zs, o.z1); ++j) {
      for (size_t i = grid_index(xs, o.x0); i < grid_index(xs, o.x1); ++i)
        open_cell[j * grid_columns + i] = 1;
    }
  }
  const Vector3d front(0, -1, 0);
  for (size_t i = 0; i + 1 < xs.size(); ++i) {
    for (size_t j = 0; j + 1 < zs.size(); ++j) {
      if (open_cell[j * grid_columns + i]) continue;
      builder.AddQuad(Vector3d(xs[i], 0, zs[j]), Vector3d(xs[i + 1], 0, zs[j]),
                      Vector3d(xs[i + 1], 0, zs[j + 1]), Vector3d(xs[i], 0, zs[j + 1]), front, options.wall);
    }
  }
  // Reveals, glass (or door) set back by `inset`, and a sill under each window.
  for (const auto& o : openings) {
    const Rgb8 reveal = options.wall;
    builder.AddQuad(Vector3d(o.x0, 0, o.z0), Vector3d(o.x0, inset, o.z0), Vector3d(o.x0, inset, o.z1),
                    Vector3d(o.x0, 0, o.z1), Vector3d::UnitX(), reveal);
    builder.AddQuad(Vector3d(o.x1, 0, o.z0), Vector3d(o.x1, inset, o.z0), Vector3d(o.x1, inset, o.z1),
                    Vector3d(o.x1, 0, o.z1), -Vector3d::UnitX(), reveal);
    builder.AddQuad(Vector3d(o.x0, 0, o.z1), Vector3d(o.x1, 0, o.z1), Vector3d(o.x1, inset, o.z1),
                    Vector3d(o.x0, inset, o.z1), -Vector3d::UnitZ(), reveal);
    if (o.z0 > 0) {
      builder.AddQuad(Vector3d(o.x0, 0, o.z0), Vector3d(o.x1, 0, o.z0), Vector3d(o.x1, inset, o.z0),
                      Vector3d(o.x0, inset, o.z0), Vector3d::UnitZ(), reveal);
    }
    builder.AddQuad(Vector3d(o.x0, inset, o.z0), Vector3d(o.x1, inset, o.z0), Vector3d(o.x1, inset, o.z1),
                    Vector3d(o.x0, inset, o.z1), front, o.door ? door_color : options.glass);
    if (!o.door) {
      // A window frame cross (mullion and transom) standing just in front of the glass.
      const double cx = (o.x0 + o.x1) / 2, cz = (o.z0 + o.z1) / 2;
      builder.AddBox(Vector3d(cx, inset - 0.03, cz), Vector3d(0.06, 0.05, o.z1 - o.z0), frame);
      builder.AddBox(Vector3d(cx, inset - 0.03, cz + 0.15 * (o.z1 - o.z0)), Vector3d(o.x1 - o.x0, 0.05, 0.06),
                     frame);
      builder.AddBox(Vector3d(cx, -0.04, o.z0 - 0.03), Vector3d(o.x1 - o.x0 + 0.1, 0.1, 0.06), frame);
    }
  }
  // The rest of the slab: back, ends, top; and a cornice.
  builder.AddQuad(Vector3d(-w / 2, d, 0), Vector3d(w / 2, d, 0), Vector3d(w / 2, d, h),
                  Vector3d(-w / 2, d, h), Vector3d::UnitY(), options.wall);
  for (int side : {-1, 1}) {
    builder.AddQuad(Vector3d(side * w / 2, 0, 0), Vector3d(side * w / 2, d, 0), Vector3d(side * w / 2, d, h),
                    Vector3d(side * w / 2, 0, h), Vector3d(side, 0, 0), options.wall);
  }
  builder.AddQuad(Vector3d(-w / 2, 0, h), Vector3d(w / 2, 0, h), Vector3d(w / 2, d, h),
                  Vector3d(-w / 2, d, h), Vector3d::UnitZ(), options.wall);
  builder.AddBox(Vector3d(0, d / 2 - 0.1, h + 0.15), Vector3d(w + 0.3, d + 0.2, 0.3), Rgb8(160, 150, 140));
  return builder.Take();
}

TriangleMesh MakeWallMesh(const Vector3d& size, Rgb8 color) {
  MeshBuilder builder(true);
  builder.AddBox(Vector3d(0, 0, size.z() / 2), size, color, true);
  builder.AddBox(Vector3d(0, 0, size.z() + 0.04), Vector3d(size.x() + 0.08, size.y() + 0.08, 0.08),
                 Rgb8(150, 148, 144));
  return builder.Take();
}

TriangleMesh SubdivideMesh(const TriangleMesh& mesh, int levels) {
  TriangleMesh current = mesh;
  for (int level = 0; level < levels; ++level) {
    TriangleMesh next;
    next.vertices = current.vertices;
    next.vertex_normals = current.vertex_normals;
    next.vertex_colors = current.vertex_colors;
    next.texture = current.texture;
    std::unordered_map<uint64_t, int> midpoint_of_edge;
    auto midpoint = [&](int a, int b) {
      const uint64_t key =
          (static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b));
      auto [it, inserted] = midpoint_of_edge.try_emplace(key, static_cast<int>(next.vertices.size()));
      if (inserted) {
        next.vertices.push_back((current.vertices[a] + current.vertices[b]) / 2);
        if (!current.vertex_normals.empty()) {
          next.vertex_normals.push_back((current.vertex_normals[a] + current.vertex_normals[b]).normalized());
        }
        if (!current.vertex_colors.empty()) {
          next.vertex_colors.push_back(
              ((current.vertex_colors[a].cast<int>() + current.vertex_colors[b].cast<int>()) / 2)
                  .cast<uint8_t>());
        }
      }
      return it->second;
    };
    for (size_t f = 0; f < current.triangles.size(); ++f) {
      const Eigen::Vector3i& t = current.triangles[f];
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.triangles.insert(next.triangles.end(),
                            {{t[0], ab, ca}, {ab, t[1], bc}, {ca, bc, t[2]}, {ab, bc, ca}});
      if (!current.triangle_colors.empty())
        next.triangle_colors.insert(next.triangle_colors.end(), 4, current.triangle_colors[f]);
    }
    if (next.texcoords.empty()) next.texture = cv::Mat();
    current = std::move(next);
  }
  return current;
}

}  // namespace lidarshop
