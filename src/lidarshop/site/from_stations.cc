#include "lidarshop/site/from_stations.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/site/grid_lookup.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

void FromStationsOptions::Check() const { Validate(*this); }

template <>
const StructInfo& InfoOf<FromStationsOptions>() {
  static const StructInfo info = [] {
    StructBuilder<FromStationsOptions> b(
        "FromStationsOptions", "fill a hole from what other stations measured, synthesize the rest");
    b.Field(&FromStationsOptions::range_noise_sigma_m, "range_noise_sigma_m",
            "σ of the stations' range noise")
        .Unit("m")
        .Min(0);
    b.Field(&FromStationsOptions::sigma_multiple, "sigma_multiple", "the margin holds this many σ").Min(0);
    b.Field(&FromStationsOptions::min_margin_m, "min_margin_m",
            "a surface is behind the removed object only this far behind it, at least")
        .Unit("m")
        .Min(0);
    b.Field(&FromStationsOptions::footprint_multiple, "footprint_multiple",
            "the ray footprint (range x angular step) times this is added to the margin")
        .Min(0);
    b.Field(&FromStationsOptions::max_range_jump_ratio, "max_range_jump_ratio",
            "mesh edges whose ranges differ by more (fraction of the nearer) are cut")
        .AboveZero();
    b.Field(&FromStationsOptions::max_incidence_deg, "max_incidence_deg",
            "triangles seen more obliquely from their station are dropped")
        .Unit("deg")
        .Range(1, 90);
    b.Field(&FromStationsOptions::object_margin_cells, "object_margin_cells",
            "the hole's rim this wide is background, not the removed object")
        .Unit("cells")
        .Range(0, 100);
    b.Field(
         &FromStationsOptions::object_distance_m, "object_distance_m",
         "a station's point this near the object's along its ray (+ 4 sigma and a footprint) is the object")
        .Unit("m")
        .Min(0);
    b.Field(&FromStationsOptions::object_min_cells, "object_min_cells",
            "regions of a station's object cells smaller than this are dropped")
        .Unit("cells")
        .Min(1);
    b.Field(&FromStationsOptions::object_grow_range_jump, "object_grow_range_jump",
            "largest relative range step between grown object cells")
        .AboveZero();
    b.Field(&FromStationsOptions::object_extent_m, "object_extent_m",
            "the object's growth stays inside its box grown by this")
        .Unit("m")
        .Min(0);
    b.Field(
         &FromStationsOptions::surface_window_cells, "surface_window_cells",
         "the range comes from a plane fitted to the other station's cells this far around the hit (0 = the "
         "triangle's)")
        .Unit("cells")
        .Range(0, 8);
    b.Field(&FromStationsOptions::check_free_space, "check_free_space",
            "the ray from the object to the hit must be seen free by some station");
    b.Field(&FromStationsOptions::free_space_step, "free_space_step",
            "free-space samples every this fraction of the range (at least 5 cm)")
        .Range(1e-4, 1);
    b.Field(&FromStationsOptions::fill_rest, "fill_rest", "synthesize the cells no station saw (FillScan)");
    b.Field(&FromStationsOptions::fill, "fill", "the fill of the cells no station saw");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FromStationsSource>() {
  static const StructInfo info = [] {
    StructBuilder<FromStationsSource> b("FromStationsSource", "another station a hole was filled from");
    b.Field(&FromStationsSource::station, "station",
            "1 + its index among the stations: its from_station tag");
    b.Field(&FromStationsSource::file, "file", "the file it was read from");
    b.Field(&FromStationsSource::scan, "scan", "its index in that file");
    b.Field(&FromStationsSource::name, "name", "its scan's name");
    b.Field(&FromStationsSource::from_station_cells, "from_station_cells", "hole cells filled from it")
        .Unit("cells");
    b.Field(&FromStationsSource::object_cells, "object_cells", "cells of the removed object seen in it")
        .Unit("cells");
    return b.Build();
  }();
  return info;
}

namespace {

// A field of FillResult read through FromStationsResult::fill, written only when the synthesis ran
// (filled_rest): the synthesis's numbers stand beside the whole hole's, in one object.
FieldInfo SynthesisField(const FieldInfo& field) {
  using Result = FromStationsResult;
  FieldInfo through = field;
  auto fill = [](const void* object) -> const void* { return &static_cast<const Result*>(object)->fill; };
  auto fill_of = [](void* object) -> void* { return &static_cast<Result*>(object)->fill; };
  through.get = [get = field.get, fill](const void* object) { return get(fill(object)); };
  if (field.set)
    through.set = [set = field.set, fill_of](void* o, const nlohmann::json& json) { set(fill_of(o), json); };
  if (field.nested_of)
    through.nested_of = [nested_of = field.nested_of, fill_of](void* o) { return nested_of(fill_of(o)); };
  if (field.list_size)
    through.list_size = [list_size = field.list_size, fill](const void* o) { return list_size(fill(o)); };
  if (field.element_of) {
    through.element_of = [element_of = field.element_of, fill_of](void* o, size_t i) {
      return element_of(fill_of(o), i);
    };
  }
  through.present = [present = field.present, fill](const void* object) {
    return static_cast<const Result*>(object)->filled_rest && (!present || present(fill(object)));
  };
  return through;
}

}  // namespace

template <>
const StructInfo& InfoOf<FromStationsResult>() {
  static const StructInfo info = [] {
    using Result = FromStationsResult;
    StructBuilder<Result> b(
        "FromStationsResult",
        "a fill from other stations: the synthesis's numbers (when it ran) and the hole's");
    b.Field(&Result::hole_cells, "hole_cells", "cells of the hole").Unit("cells");
    b.Field(&Result::synthesized_cells, "synthesized_cells", "hole cells the synthesis gave a return")
        .Unit("cells");
    b.Field(&Result::no_return_cells, "no_return_cells", "hole cells left without a return").Unit("cells");
    b.Field(&Result::warnings, "warnings",
            "the synthesis's warnings and what looks wrong, one sentence each");
    b.Field(&Result::from_station_cells, "from_station_cells", "hole cells filled from another station")
        .Unit("cells");
    b.Field(&Result::stations, "stations", "the other stations, in order");
    b.Field(&Result::rim_cells, "rim_cells",
            "cells whose hit was a rim, unconfirmed or too oblique (left to the synthesis)")
        .Unit("cells");
    b.Field(&Result::not_free_cells, "not_free_cells", "cells whose hit failed the free-space check")
        .Unit("cells");
    b.Field(&Result::stations_seconds, "stations_seconds", "the cast into the other stations").Unit("s");
    b.Field(&Result::fill_seconds, "fill_seconds", "the synthesis").Unit("s");
    StructInfo own = b.Build();
    // FillResult's order, its hole counts and warnings replaced by the whole hole's, then the rest.
    std::vector<FieldInfo> fields;
    for (const FieldInfo& field : InfoOf<FillResult>().fields) {
      const FieldInfo* mine = own.Find(field.key);
      fields.push_back(mine != nullptr ? *mine : SynthesisField(field));
    }
    for (const FieldInfo& field : own.fields) {
      if (InfoOf<FillResult>().Find(field.key) == nullptr) fields.push_back(field);
    }
    own.fields = std::move(fields);
    return own;
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FillWithStationsOptions>() {
  static const StructInfo info = [] {
    StructBuilder<FillWithStationsOptions> b(
        "FillWithStationsOptions", "what fill --stations used: the fill's options and the stations'");
    b.Flatten(&FillWithStationsOptions::fill);
    b.Field(&FillWithStationsOptions::from_stations, "from_stations", "the fill from the other stations");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RemoveWithStationsOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RemoveWithStationsOptions> b(
        "RemoveWithStationsOptions", "what remove --stations used: the removal's options and the stations'");
    b.Flatten(&RemoveWithStationsOptions::remove);
    b.Field(&RemoveWithStationsOptions::from_stations, "from_stations", "the fill from the other stations");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RemoveFromStationsResult>() {
  static const StructInfo info = [] {
    StructBuilder<RemoveFromStationsResult> b("RemoveFromStationsResult",
                                              "an object removal filled from other stations first");
    b.Field(&RemoveFromStationsResult::cut, "cut", "the object's cut");
    b.Field(&RemoveFromStationsResult::filled, "fill", "the fill of its hole");
    b.Field(&RemoveFromStationsResult::warnings, "warnings", "the cut's then the fill's, one sentence each");
    return b.Build();
  }();
  return info;
}

namespace {

constexpr double kMinFreeSpaceStep = 0.05;  // metres

double Margin(const FromStationsOptions& o, double range, double step_rad) {
  return o.min_margin_m + o.sigma_multiple * o.range_noise_sigma_m + o.footprint_multiple * range * step_rad;
}

Eigen::Vector3d Apply(const Eigen::Matrix4d& t, const Eigen::Vector3d& p) {
  return t.topLeftCorner<3, 3>() * p + t.topRightCorner<3, 1>();
}

Eigen::Vector3d PointOf(const Scan& scan, int row, int col) {
  const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
  return Eigen::Vector3d(p[0], p[1], p[2]);
}

// An other station prepared: where it stands relative to the scan, its object cells, its mesh's triangles.
struct Station {
  const Scan* scan = nullptr;
  GridLookup grid;
  Eigen::Matrix4d scan_from_station, station_from_scan;
  double step_rad = 0;
  cv::Mat object;                                  // CV_8U 255 = the removed object seen by this station
  std::vector<std::array<int, 3>> triangle_cells;  // per mesh triangle: row * cols + col of its corners
  std::vector<uint8_t> triangle_rim;               // per mesh triangle: 1 = a corner on a border
  explicit Station(const Scan& s) : scan(&s), grid(s) {}
};

// Step 1 of the header: the removed object as `station` saw it, and the box (scan frame) it stays in.
void MarkObject(const Scan& scan, const GridLookup& scan_grid, const cv::Mat& object_in_scan,
                const cv::Mat& hole, const Eigen::AlignedBox3d& object_box, const FromStationsOptions& o,
                Station* station, Eigen::AlignedBox3d* grown_box) {
  const Scan& b = *station->scan;
  cv::Mat seed(b.rows, b.cols, CV_8U, cv::Scalar(0));
  cv::Mat seen_by_scan(b.rows, b.cols, CV_8U, cv::Scalar(0));  // background this scan measured
  const double scan_step = scan_grid.step_rad();
  ParallelFor(b.rows, [&](int64_t row64) {
    const int row = static_cast<int>(row64);
    for (int col = 0; col < b.cols; ++col) {
      if (b.valid.at<uint8_t>(row, col) == 0) continue;
      const Eigen::Vector3d p = Apply(station->scan_from_station, PointOf(b, row, col));
      int r = 0, c = 0;
      if (!scan_grid.Cell(p, &r, &c)) continue;
      const double d = p.norm(), margin = Margin(o, d, scan_step);
      if (hole.at<uint8_t>(r, c) == 0 && scan.valid.at<uint8_t>(r, c) != 0 &&
          std::abs(scan.range.at<float>(r, c) - d) <= margin) {
        seen_by_scan.at<uint8_t>(row, col) = 255;
        continue;
      }
      // The same surface as the object's point on that ray: within the distance, the noise and one footprint
      // (neighbouring rays of a grazing surface differ by about that much).
      const double same = o.object_distance_m + o.sigma_multiple * o.range_noise_sigma_m + d * scan_step;
      if (object_in_scan.at<uint8_t>(r, c) != 0 && scan.valid.at<uint8_t>(r, c) != 0 &&
          std::abs(scan.range.at<float>(r, c) - d) <= same)
        seed.at<uint8_t>(row, col) = 255;
    }
  });
  cv::Mat object = WithoutSmallRegions(seed, o.object_min_cells);
  Eigen::AlignedBox3d box = object_box;
  for (int r = 0; r < b.rows; ++r)
    for (int c = 0; c < b.cols; ++c)
      if (object.at<uint8_t>(r, c) != 0) box.extend(Apply(station->scan_from_station, PointOf(b, r, c)));
  const Eigen::AlignedBox3d bound(box.min() - Eigen::Vector3d::Constant(o.object_extent_m),
                                  box.max() + Eigen::Vector3d::Constant(o.object_extent_m));
  // Breadth-first growth in row order: the result does not depend on threads.
  std::deque<std::pair<int, int>> queue;
  for (int r = 0; r < b.rows; ++r)
    for (int c = 0; c < b.cols; ++c)
      if (object.at<uint8_t>(r, c) != 0) queue.emplace_back(r, c);
  while (!queue.empty()) {
    const auto [r, c] = queue.front();
    queue.pop_front();
    const float range = b.range.at<float>(r, c);
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        const int rr = r + dr, cc = c + dc;
        if (rr < 0 || cc < 0 || rr >= b.rows || cc >= b.cols || object.at<uint8_t>(rr, cc) != 0 ||
            b.valid.at<uint8_t>(rr, cc) == 0 || seen_by_scan.at<uint8_t>(rr, cc) != 0)
          continue;
        if (std::abs(b.range.at<float>(rr, cc) - range) > o.object_grow_range_jump * range) continue;
        const Eigen::Vector3d p = Apply(station->scan_from_station, PointOf(b, rr, cc));
        if (!bound.contains(p)) continue;
        object.at<uint8_t>(rr, cc) = 255;
        box.extend(p);
        queue.emplace_back(rr, cc);
      }
    }
  }
  station->object = object;
  if (!box.isEmpty()) grown_box->extend(box);
}

// Step 2: the station's returns outside the object as triangles in the scan's frame, added to `scene` under id
// `id`.
void AddMesh(const FromStationsOptions& o, int id, Station* station, RaycastScene* scene) {
  const Scan& b = *station->scan;
  const int rows = b.rows, cols = b.cols;
  const float ratio = static_cast<float>(o.max_range_jump_ratio);
  auto usable = [&](int r, int c) {
    return b.valid.at<uint8_t>(r, c) != 0 && station->object.at<uint8_t>(r, c) == 0;
  };
  auto joined = [&](int r0, int c0, int r1, int c1) {
    const float a = b.range.at<float>(r0, c0), d = b.range.at<float>(r1, c1);
    return std::abs(a - d) <= ratio * std::min(a, d);
  };
  // A cell is inside a surface when it and its 8 neighbours are usable and joined to it.
  cv::Mat inside(rows, cols, CV_8U, cv::Scalar(0));
  for (int r = 1; r + 1 < rows; ++r) {
    for (int c = 1; c + 1 < cols; ++c) {
      if (!usable(r, c)) continue;
      bool all = true;
      for (int dr = -1; dr <= 1 && all; ++dr)
        for (int dc = -1; dc <= 1 && all; ++dc) all = usable(r + dr, c + dc) && joined(r, c, r + dr, c + dc);
      inside.at<uint8_t>(r, c) = all ? 1 : 0;
    }
  }
  const double min_cos = std::cos(o.max_incidence_deg * M_PI / 180.0);
  const Eigen::Vector3d origin = Apply(station->scan_from_station, Eigen::Vector3d::Zero());
  TriangleMesh mesh;
  std::vector<int> vertex_of_cell(static_cast<size_t>(rows) * cols, -1);
  auto vertex = [&](int cell) {
    if (vertex_of_cell[cell] < 0) {
      vertex_of_cell[cell] = static_cast<int>(mesh.vertices.size());
      mesh.vertices.push_back(
          Apply(station->scan_from_station, PointOf(b, cell / cols, cell % cols)).cast<float>());
    }
    return vertex_of_cell[cell];
  };
  auto add = [&](int a, int c1, int c2) {
    const Eigen::Vector3d pa = Apply(station->scan_from_station, PointOf(b, a / cols, a % cols));
    const Eigen::Vector3d p1 = Apply(station->scan_from_station, PointOf(b, c1 / cols, c1 % cols));
    const Eigen::Vector3d p2 = Apply(station->scan_from_station, PointOf(b, c2 / cols, c2 % cols));
    const Eigen::Vector3d normal = (p1 - pa).cross(p2 - pa);
    const Eigen::Vector3d view = (pa + p1 + p2) / 3.0 - origin;
    if (normal.norm() <= 0 || std::abs(normal.dot(view)) < min_cos * normal.norm() * view.norm()) return;
    mesh.triangles.emplace_back(vertex(a), vertex(c1), vertex(c2));
    station->triangle_cells.push_back({a, c1, c2});
    const bool rim = !inside.at<uint8_t>(a / cols, a % cols) || !inside.at<uint8_t>(c1 / cols, c1 % cols) ||
                     !inside.at<uint8_t>(c2 / cols, c2 % cols);
    station->triangle_rim.push_back(rim ? 1 : 0);
  };
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c + 1 < cols; ++c) {
      const bool va = usable(r, c), vb = usable(r, c + 1), vc = usable(r + 1, c), vd = usable(r + 1, c + 1);
      const int a = r * cols + c, bb = a + 1, cc = a + cols, d = cc + 1;
      const bool bc = vb && vc && joined(r, c + 1, r + 1, c);
      if (va && bc && joined(r, c, r + 1, c) && joined(r, c, r, c + 1)) add(a, cc, bb);
      if (vd && bc && joined(r, c + 1, r + 1, c + 1) && joined(r + 1, c, r + 1, c + 1)) add(bb, cc, d);
    }
  }
  if (!mesh.triangles.empty()) scene->AddMesh(mesh, id);
}

// Step 4: whether some station saw the ray free from `t_from` to `t_to` (scan frame, along unit `direction`).
bool SeenFree(const std::vector<Station>& stations, const Eigen::AlignedBox3d& object_box,
              const Eigen::Vector3d& direction, double t_from, double t_to, const FromStationsOptions& o) {
  for (double t = t_from; t < t_to; t += std::max(kMinFreeSpaceStep, o.free_space_step * t)) {
    const Eigen::Vector3d p = direction * t;
    bool free = false;
    for (const Station& s : stations) {
      const Eigen::Vector3d q = Apply(s.station_from_scan, p);
      int r = 0, c = 0;
      if (!s.grid.Cell(q, &r, &c) || s.scan->valid.at<uint8_t>(r, c) == 0) continue;
      const double d = q.norm(), range = s.scan->range.at<float>(r, c);
      if (range >= d - Margin(o, d, s.step_rad) ||
          (s.object.at<uint8_t>(r, c) != 0 && object_box.contains(p))) {
        free = true;
        break;
      }
    }
    if (!free) return false;
  }
  return true;
}

// Step 5's range: the ray met the triangle at `t`, whose plane has unit `triangle_normal` (scan frame). The
// plane fitted (least squares) to the station's points of the (2 surface_window_cells + 1)² cells around
// `center` that lie on that triangle's surface (within 4 σ of its plane) gives the range where the ray meets
// the measured surface, with the noise of one point averaged over the window's. A hit whose surface the window
// does not confirm (under half its cells on it, or they lie along a line: a triangle across a crease or a
// window's edge), or that this
// scan's ray meets more obliquely than max_incidence_deg (where a millimetre across the surface is centimetres
// along the ray), is not trusted: -1.
double SurfaceRange(const Station& s, const cv::Point& center, const Eigen::Vector3d& direction, double t,
                    const Eigen::Vector3d& triangle_normal, const FromStationsOptions& o) {
  const double min_cos = std::cos(o.max_incidence_deg * M_PI / 180.0);
  const int k = o.surface_window_cells;
  if (k <= 0) return std::abs(triangle_normal.dot(direction)) >= min_cos ? t : -1.0;
  const Scan& b = *s.scan;
  const double tolerance = o.sigma_multiple * o.range_noise_sigma_m;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  int n = 0;
  for (int r = std::max(0, center.y - k); r <= std::min(b.rows - 1, center.y + k); ++r) {
    for (int c = std::max(0, center.x - k); c <= std::min(b.cols - 1, center.x + k); ++c) {
      if (b.valid.at<uint8_t>(r, c) == 0 || s.object.at<uint8_t>(r, c) != 0) continue;
      const Eigen::Vector3d p = Apply(s.scan_from_station, PointOf(b, r, c)) - direction * t;  // near 0
      if (std::abs(triangle_normal.dot(p)) > tolerance) continue;
      sum += p;
      outer += p * p.transpose();
      ++n;
    }
  }
  // Half the window on the surface at least, spread in two directions (not the line of a crease).
  if (n < std::max(6, (2 * k + 1) * (2 * k + 1) / 2)) return -1.0;
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Matrix3d covariance = outer / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  if (solver.eigenvalues()(1) < 0.01 * solver.eigenvalues()(2)) return -1.0;
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  const double along = normal.dot(direction);
  if (std::abs(along) < min_cos) return -1.0;
  const double shift = normal.dot(mean) / along;  // from the triangle's hit to the plane, along the ray
  return std::abs(shift) <= t * s.step_rad + tolerance ? t + shift : -1.0;
}

// Where the ray from the origin along unit `direction` enters `box` (0 when it starts inside), or -1 when it
// misses it.
double EntryDistance(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& direction) {
  if (box.isEmpty()) return -1;
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(direction[axis]) < 1e-12) {
      if (box.min()[axis] > 0 || box.max()[axis] < 0) return -1;
      continue;
    }
    double a = box.min()[axis] / direction[axis], b = box.max()[axis] / direction[axis];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1 ? t0 : -1;
}

}  // namespace

FromStationsResult FillFromStations(const Scan& scan, const cv::Mat& hole_in,
                                    const std::vector<Scan>& other_stations,
                                    const FromStationsOptions& options, Progress* progress) {
  options.Check();
  CheckScan(scan);
  if (hole_in.rows != scan.rows || hole_in.cols != scan.cols || hole_in.channels() != 1)
    throw InputError(fmt::format("the hole mask is {} x {}, the scan '{}' {} x {}", hole_in.cols,
                                 hole_in.rows, scan.name, scan.cols, scan.rows));
  if (scan.rows < 2 || scan.cols < 2)
    throw InputError(
        fmt::format("scan '{}' has no grid: an unorganized cloud cannot be filled from stations", scan.name));
  const cv::Mat hole = hole_in != 0;
  for (size_t i = 0; i < other_stations.size(); ++i) {
    CheckScan(other_stations[i]);
    if (!HasRayDirections(other_stations[i]) || other_stations[i].rows < 2 || other_stations[i].cols < 2)
      throw InputError(fmt::format("station {} ('{}') has no grid: an unorganized cloud cannot fill a hole",
                                   i, other_stations[i].name));
  }
  Timer timer;
  FromStationsResult result;
  result.hole_cells = cv::countNonZero(hole);
  result.from_station = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
  result.cells_per_station.assign(other_stations.size(), 0);
  Scan filled = Clone(scan);
  if (filled.from_station.empty()) filled.from_station = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);

  const GridLookup scan_grid(scan);
  // The removed object's points: the hole's returns less its rim.
  cv::Mat object_in_scan = hole.clone();
  if (options.object_margin_cells > 0) {
    const int k = 2 * options.object_margin_cells + 1;
    cv::erode(hole, object_in_scan, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
  }
  object_in_scan &= scan.valid != 0;
  if (cv::countNonZero(object_in_scan) == 0) object_in_scan = hole & (scan.valid != 0);
  Eigen::AlignedBox3d object_box;
  for (int r = 0; r < scan.rows; ++r)
    for (int c = 0; c < scan.cols; ++c)
      if (object_in_scan.at<uint8_t>(r, c) != 0) object_box.extend(PointOf(scan, r, c));

  std::vector<Station> stations;
  RaycastScene scene;
  Eigen::AlignedBox3d grown_box = object_box;
  if (result.hole_cells > 0) {
    for (size_t k = 0; k < other_stations.size(); ++k) {
      Station& s = stations.emplace_back(other_stations[k]);
      s.scan_from_station = scan.world_from_scanner.inverse() * other_stations[k].world_from_scanner;
      s.station_from_scan = s.scan_from_station.inverse();
      s.step_rad = s.grid.step_rad();
      MarkObject(scan, scan_grid, object_in_scan, hole, object_box, options, &s, &grown_box);
      AddMesh(options, static_cast<int>(k), &s, &scene);
      if (progress != nullptr) progress->Advance();
    }
  }
  for (const Station& s : stations) {
    result.object_in_station.push_back(s.object);
    result.object_cells.push_back(cv::countNonZero(s.object));
  }
  const Eigen::AlignedBox3d object_bound =
      grown_box.isEmpty()
          ? grown_box
          : Eigen::AlignedBox3d(grown_box.min() - Eigen::Vector3d::Constant(options.object_extent_m),
                                grown_box.max() + Eigen::Vector3d::Constant(options.object_extent_m));

  // Step 3: the hole's rays.
  std::vector<cv::Point> cells;
  cv::findNonZero(hole, cells);
  if (scene.num_meshes() > 0 && !cells.empty()) {
    scene.Commit();
    const double scan_step = scan_grid.step_rad();
    std::vector<Ray> rays(cells.size());
    const RayDirections scan_rays(scan);
    for (size_t i = 0; i < cells.size(); ++i) {
      const cv::Vec3f d = scan_rays(cells[i].y, cells[i].x);
      Ray& ray = rays[i];
      ray.direction = Eigen::Vector3f(d[0], d[1], d[2]).normalized();
      const bool returned = scan.valid.at<uint8_t>(cells[i]) != 0;
      const double range = returned ? scan.range.at<float>(cells[i]) : 0.0;
      // Without a return (a dark window of the object): from where the ray enters the object's box.
      ray.t_near = static_cast<float>(
          returned ? range + Margin(options, range, scan_step)
                   : std::max(0.0, EntryDistance(object_bound, ray.direction.cast<double>())));
    }
    std::vector<RayHit> hits(cells.size());
    scene.Cast(rays, hits);
    // Step 4 and 5, each cell on its own.
    std::vector<uint8_t> outcome(cells.size(), 0);  // 0 no hit, 1 taken, 2 rim, 3 not free
    constexpr int64_t kChunk = 4096;
    ParallelForRange(
        static_cast<int64_t>(cells.size()),
        [&](int64_t begin, int64_t end) {
          for (int64_t i = begin; i < end; ++i) {
            const RayHit& hit = hits[i];
            if (!hit.hit()) continue;
            const Station& s = stations[hit.geometry_id];
            if (s.triangle_rim[hit.primitive_id]) {
              outcome[i] = 2;
              continue;
            }
            const Eigen::Vector3d direction = rays[i].direction.cast<double>();
            const double t = hit.t_hit;
            if (options.check_free_space && !SeenFree(stations, object_bound, direction, rays[i].t_near,
                                                      t - Margin(options, t, scan_step), options)) {
              outcome[i] = 3;
              continue;
            }
            const cv::Point cell = cells[i];
            const Scan& b = *s.scan;
            const std::array<int, 3>& corner = s.triangle_cells[hit.primitive_id];
            const double w[3] = {1.0 - hit.u - hit.v, hit.u, hit.v};
            const cv::Point at[3] = {{corner[0] % b.cols, corner[0] / b.cols},
                                     {corner[1] % b.cols, corner[1] / b.cols},
                                     {corner[2] % b.cols, corner[2] / b.cols}};
            const int nearest = static_cast<int>(std::max_element(w, w + 3) - w);
            const double t_surface =
                SurfaceRange(s, at[nearest], direction, t, hit.normal.cast<double>().normalized(), options);
            if (t_surface <= 0) {
              outcome[i] = 2;  // an edge the other station's surface does not confirm
              continue;
            }
            outcome[i] = 1;
            filled.valid.at<uint8_t>(cell) = kValid;
            filled.range.at<float>(cell) = static_cast<float>(t_surface);
            filled.point.at<cv::Vec3f>(cell) =
                cv::Vec3f(rays[i].direction.x(), rays[i].direction.y(), rays[i].direction.z()) *
                static_cast<float>(t_surface);
            if (filled.has_intensity()) {
              double value = 0.5;
              if (b.has_intensity()) {
                value = 0;
                for (int j = 0; j < 3; ++j) value += w[j] * b.intensity.at<float>(at[j]);
              }
              filled.intensity.at<float>(cell) = static_cast<float>(std::clamp(value, 0.0, 1.0));
            }
            if (filled.has_color()) {
              cv::Vec3d value(0, 0, 0);
              if (b.has_color())
                for (int j = 0; j < 3; ++j) value += w[j] * cv::Vec3d(b.color.at<cv::Vec3b>(at[j]));
              filled.color.at<cv::Vec3b>(cell) =
                  cv::Vec3b(cv::saturate_cast<uint8_t>(value[0]), cv::saturate_cast<uint8_t>(value[1]),
                            cv::saturate_cast<uint8_t>(value[2]));
            }
            if (!filled.label.empty())
              filled.label.at<int32_t>(cell) = b.label.empty() ? kNoLabel : b.label.at<int32_t>(at[nearest]);
            if (!filled.normal.empty()) {
              // The hit's face, in the scan's frame, turned towards the scan's scanner.
              Eigen::Vector3f n = hit.normal.normalized();
              if (n.dot(rays[i].direction) > 0) n = -n;
              filled.normal.at<cv::Vec3f>(cell) = cv::Vec3f(n.x(), n.y(), n.z());
            }
            if (!filled.curvature.empty()) filled.curvature.at<float>(cell) = NAN;
            if (!filled.true_range.empty()) filled.true_range.at<float>(cell) = 0.0f;  // no truth here
            if (!filled.synthesized.empty()) filled.synthesized.at<uint8_t>(cell) = 0;
            for (auto& [name, values] : filled.attributes) {
              const int bytes = static_cast<int>(values.elemSize());
              std::fill_n(values.ptr<uint8_t>(cell.y) + bytes * cell.x, bytes, 0);
            }
            const uint8_t tag = static_cast<uint8_t>(std::min<int>(hit.geometry_id + 1, 255));
            filled.from_station.at<uint8_t>(cell) = tag;
            result.from_station.at<uint8_t>(cell) = tag;
          }
          if (progress != nullptr) progress->Advance((end - begin + kChunk - 1) / kChunk);
        },
        kChunk);
    for (size_t i = 0; i < cells.size(); ++i) {
      if (outcome[i] == 1) {
        ++result.from_station_cells;
        ++result.cells_per_station[hits[i].geometry_id];
      }
      result.rim_cells += outcome[i] == 2;
      result.not_free_cells += outcome[i] == 3;
    }
  }
  result.stations_seconds = timer.Seconds();

  // The rest: synthesized around the real cells.
  timer.Restart();
  const cv::Mat rest = hole & (result.from_station == 0);
  const int64_t rest_cells = cv::countNonZero(rest);
  if (rest_cells > 0 && options.fill_rest) {
    result.fill = FillScan(MaskScan(filled, rest == 0), rest, options.fill);
    result.filled_rest = true;
    result.scan = result.fill.scan;
    result.synthesized = result.fill.filled.clone();
    for (const std::string& warning : result.fill.warnings) result.warnings.push_back(warning);
  } else {
    result.scan = rest_cells > 0 ? MaskScan(filled, rest == 0) : filled;
    result.synthesized = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
  }
  result.fill_seconds = timer.Seconds();
  result.synthesized_cells = cv::countNonZero(result.synthesized);
  result.no_return_cells = result.hole_cells - result.from_station_cells - result.synthesized_cells;
  if (other_stations.empty())
    result.warnings.push_back("no other station was given: every hole cell was synthesized");
  for (size_t k = 0; k < other_stations.size(); ++k) {
    FromStationsSource& source = result.stations.emplace_back();
    source.station = static_cast<int64_t>(k) + 1;
    source.name = other_stations[k].name;
    source.from_station_cells = result.cells_per_station[k];
    source.object_cells = k < result.object_cells.size() ? result.object_cells[k] : 0;
  }
  return result;
}

RemoveFromStationsResult RemoveObjectFromStations(const Scan& scan, const cv::Mat& strokes,
                                                  const std::vector<Scan>& other_stations,
                                                  const RemoveOptions& remove, FromStationsOptions from,
                                                  Progress* progress) {
  remove.Check();
  RemoveFromStationsResult result;
  result.cut = SegmentObject(scan, strokes, remove.segment);
  // As RemoveObject: the cut's cells with a return, the enclosed no-return cells, grown by the margin.
  cv::Mat object = (result.cut.mask != 0) & (scan.valid != 0);
  if (remove.fill_enclosed_no_return) object |= EnclosedNoReturnCells(object, scan.valid);
  result.hole = GrowHole(object, remove.margin_cells);
  from.object_margin_cells = remove.margin_cells;
  from.fill = remove.fill;
  result.filled = FillFromStations(scan, result.hole, other_stations, from, progress);
  if (remove.keep_object) {
    const cv::Mat given = (result.filled.from_station != 0) | (result.filled.synthesized != 0);
    result.behind = MaskScan(result.filled.scan, given & (result.cut.mask != 0));
  }
  result.warnings = result.cut.warnings;
  result.warnings.insert(result.warnings.end(), result.filled.warnings.begin(), result.filled.warnings.end());
  return result;
}

}  // namespace lidarshop
