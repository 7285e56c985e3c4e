// Procedural meshes for scene descriptions: the analytic primitives (plane, box, sphere,
// cylinder, cone) and the man-made objects of the built-in scenes (cars, a lamp post, an electric
// box, a mailbox, a façade, a wall).
//
// Frames and units: metres, object frame z up. The analytic primitives are centred at their origin (plane:
// normal +z, `size` = x, y extents; box: `size` = x, y, z extents; cylinder and cone: axis +z, z in [-h/2,
// h/2], the cone's apex at +h/2). The man-made objects stand on z = 0 with their origin at the centre of
// their footprint; their front faces -y (a scanner at the origin looking along +y sees the front of an object
// placed at y > 0); cars are long along y with the bonnet towards -y.
//
// Triangles are counter-clockwise seen from outside. Curved surfaces carry smooth `vertex_normals` (so a
// scanner reports the analytic normal up to interpolation); flat faces carry their face normal. Composite
// objects carry `triangle_colors` (paint, glass, tyres, ...); the analytic primitives carry none.
#pragma once

#include <string>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

TriangleMesh MakePlaneMesh(const Eigen::Vector2d& size);
TriangleMesh MakeBoxMesh(const Eigen::Vector3d& size);
// UV sphere: `segments` around the z axis (>= 3), segments / 2 rings from pole to pole.
TriangleMesh MakeSphereMesh(double radius, int segments = 96);
// Closed cylinder with flat caps, `segments` around the axis (>= 3).
TriangleMesh MakeCylinderMesh(double radius, double height, int segments = 64);
// Closed cone: base disc at z = -h/2, apex at z = +h/2.
TriangleMesh MakeConeMesh(double radius, double height, int segments = 64);

enum class CarStyle { kSedan, kHatchback, kVan };
template <>
const EnumInfo& EnumInfoOf<CarStyle>();
// Throws InputError naming `what` for an unknown style ("sedan", "hatchback", "van"; "suv" = "van").
CarStyle ParseCarStyle(const std::string& style, const std::string& what);

struct CarMeshOptions {
  CarStyle style = CarStyle::kSedan;
  Rgb8 paint = Rgb8(30, 60, 140);  // body colour, RGB
  int wheel_segments = 48;         // facets around each wheel (>= 8)
  // Each triangle is split into 4^subdivisions (flat midpoint subdivision: same shape, more triangles). A
  // sedan has about 870 triangles at 0; subdivisions = 4 gives about 220,000 (benchmarks of verification),
  // 5 about 890,000.
  int subdivisions = 0;
  void Check() const;
};
template <>
const StructInfo& InfoOf<CarMeshOptions>();
// A believable car silhouette: extruded side profiles for the body and the glass house, four wheels, lights.
// Sizes: sedan 4.6 x 1.8 x 1.45 m, hatchback 4.0 x 1.75 x 1.5 m, van/SUV 4.9 x 1.95 x 1.95 m (length x width
// x height). Standing on z = 0, length along y, bonnet towards -y.
TriangleMesh MakeCarMesh(const CarMeshOptions& options);

// A street lamp, about 6 m: base, tapered pole, an arm reaching towards -y and a lamp head.
TriangleMesh MakeLampPostMesh(double height = 6.0, int segments = 24);
// A roadside electric cabinet (0.9 x 0.45 x 1.35 m on a concrete plinth), two doors with handles.
TriangleMesh MakeElectricBoxMesh(Rgb8 paint = Rgb8(118, 138, 112));
// A US-style mailbox on a wooden post: box with a rounded top (0.5 m long), a red flag; about 1.25 m high.
TriangleMesh MakeMailboxMesh(Rgb8 paint = Rgb8(60, 62, 66), int segments = 24);
// A building façade: a slab of `width` x `height` (x, z) and `depth` (y, behind the front face
// at y = 0), with `floors` rows of `windows_per_floor` recessed windows (glass set back 0.15
// m, dark blue-grey) and a door.
struct FacadeMeshOptions {
  double width = 20.0;  // metres along x
  double height = 9.0;  // metres along z
  double depth = 0.5;   // metres along y (the slab's thickness)
  int floors = 3;
  int windows_per_floor = 6;
  Rgb8 wall = Rgb8(214, 200, 178);
  Rgb8 glass = Rgb8(52, 64, 80);
  void Check() const;
};
template <>
const StructInfo& InfoOf<FacadeMeshOptions>();
TriangleMesh MakeFacadeMesh(const FacadeMeshOptions& options);
// A free-standing wall: `size` = length (x), thickness (y), height (z), with a coping slab on top.
TriangleMesh MakeWallMesh(const Eigen::Vector3d& size, Rgb8 color = Rgb8(170, 80, 60));

// Splits every triangle into 4 (midpoint, edges shared), `levels` times: the same shape with 4^levels times
// the triangles. Keeps triangle colours; interpolates vertex normals and colours; drops texture coordinates.
TriangleMesh SubdivideMesh(const TriangleMesh& mesh, int levels);

}  // namespace lidarshop
