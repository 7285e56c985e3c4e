#include "lidarshop/fill/facade_lattice.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "lidarshop/pointset/planes.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void FacadeLatticeOptions::Check() const { Validate(*this); }

namespace fill_internal {
namespace {

// cos 37°: a surface whose normal is this close to the vertical is ground, a roof or a sill's top.
constexpr float kLevelNormalZ = 0.8f;
// The pitch is sought at the best shift divided by 2 .. kMaxDivisor, within ±kDivisorReach of it.
constexpr int kMaxDivisor = 4;
constexpr double kDivisorReach = 0.05;
// A known cell that differs from what its translates agree on by more than this (grey levels, RMS over the
// features) is an exception to the lattice.
constexpr double kExceptionGrey = 20.0;
// The coarse grid of shifts, metres.
constexpr double kCoarseStepM = 0.05;
// How far a pitch's score rises above the lowest score at shorter shifts (the score is 1 − mean squared
// difference / (2 · variance): a rise of 0.5 is a fall of the difference by the features' variance).
constexpr double kMinProminence = 0.5;
// Known cells of a plane's region that make a pitch worth seeking.
constexpr size_t kMinRegionCells = 100;
// Points of the region the plane is refitted to at most.
constexpr size_t kMaxRefitPoints = 20000;
// An exception is wider than this, metres (frame bars are not; doors and shop windows are).
constexpr double kExceptionReachM = 0.25;
// Colour (at most 3 channels) and relief.
constexpr int kMaxFeatures = 4;
// Translates that vote, per axis (the nearest valid ones).
constexpr size_t kVoters = 5;

// The scan's angular grid, for finding the cell whose ray passes through a point.
class AngularGrid {
 public:
  // False when the grid does not match the scan or is not monotonic.
  bool Init(const ScanGrid& grid, int rows, int cols) {
    if (static_cast<int>(grid.azimuth_rad.size()) != cols ||
        static_cast<int>(grid.elevation_rad.size()) != rows)
      return false;
    azimuth_ = grid.azimuth_rad;
    elevation_ = grid.elevation_rad;
    // Azimuths unwrapped from the first column (a full turn may cross ±π).
    for (size_t i = 1; i < azimuth_.size(); ++i)
      azimuth_[i] = azimuth_[i - 1] + WrapAngle(azimuth_[i] - azimuth_[i - 1]);
    for (size_t i = 1; i < azimuth_.size(); ++i)
      if (!(azimuth_[i] > azimuth_[i - 1])) return false;
    for (size_t i = 1; i < elevation_.size(); ++i)
      if (!(elevation_[i] < elevation_[i - 1])) return false;
    if (azimuth_.size() < 2 || elevation_.size() < 2) return false;
    azimuth_step_ = (azimuth_.back() - azimuth_.front()) / static_cast<double>(azimuth_.size() - 1);
    elevation_step_ = (elevation_.front() - elevation_.back()) / static_cast<double>(elevation_.size() - 1);
    return true;
  }

  double spacing_rad() const { return std::min(azimuth_step_, elevation_step_); }

  // The cell (row, col) whose ray is nearest the direction of `p` (scanner frame), or false when `p` lies
  // outside the grid.
  bool CellOf(const Eigen::Vector3d& p, int* row, int* col) const {
    const double r = p.norm();
    if (!(r > 0)) return false;
    // In [first column, first column + 2π): a full turn's seam lies just left of the first column; a point
    // less than half a column left of it belongs to the first column.
    double azimuth = azimuth_.front() + M_PI + WrapAngle(std::atan2(p.x(), p.y()) - azimuth_.front() - M_PI);
    if (azimuth > azimuth_.back() + 0.5 * azimuth_step_) azimuth -= 2.0 * M_PI;
    const double elevation = std::asin(std::clamp(p.z() / r, -1.0, 1.0));
    const int c = Nearest(azimuth_, azimuth, 0.5 * azimuth_step_, false);
    const int y = Nearest(elevation_, elevation, 0.5 * elevation_step_, true);
    if (c < 0 || y < 0) return false;
    *row = y;
    *col = c;
    return true;
  }

 private:
  static int Nearest(const std::vector<double>& values, double v, double reach, bool decreasing) {
    const double first = values.front(), last = values.back();
    if (decreasing ? (v > first + reach || v < last - reach) : (v < first - reach || v > last + reach))
      return -1;
    const auto it = decreasing ? std::lower_bound(values.begin(), values.end(), v, std::greater<double>())
                               : std::lower_bound(values.begin(), values.end(), v);
    size_t i = static_cast<size_t>(it - values.begin());
    if (i == values.size()) return static_cast<int>(values.size() - 1);
    if (i > 0 && std::abs(values[i - 1] - v) <= std::abs(values[i] - v)) --i;
    return static_cast<int>(i);
  }

  std::vector<double> azimuth_, elevation_;
  double azimuth_step_ = 0, elevation_step_ = 0;
};

// A plane and its axes: u along its horizontal, v up it.
struct PlaneFrame {
  Eigen::Vector3d normal, u_axis, v_axis, origin;  // u along the plane's horizontal, v up it
  double offset_m = 0;
  double SignedDistance(const Eigen::Vector3d& x) const { return normal.dot(x) + offset_m; }
  double U(const Eigen::Vector3d& x) const { return u_axis.dot(x - origin); }
  double V(const Eigen::Vector3d& x) const { return v_axis.dot(x - origin); }
};

// The frame of the upright plane n · x + offset = 0, the scanner on its positive side.
PlaneFrame MakeFrame(const Eigen::Vector3d& normal, double offset_m) {
  PlaneFrame plane;
  const double sign = offset_m < 0 ? -1.0 : 1.0;
  plane.normal = sign * normal;
  plane.offset_m = sign * offset_m;
  plane.u_axis = plane.normal.cross(Eigen::Vector3d::UnitZ()).normalized();
  plane.v_axis = plane.u_axis.cross(plane.normal);
  if (plane.v_axis.z() < 0) plane.v_axis = -plane.v_axis;
  plane.origin = -plane.offset_m * plane.normal;
  return plane;
}

// Where the ray of cell (y, x) meets the plane in front of the scanner; false when it does not.
bool RayPoint(const cv::Mat& direction, const PlaneFrame& plane, int y, int x, Eigen::Vector3d* point) {
  const cv::Vec3f d = direction.at<cv::Vec3f>(y, x);
  const Eigen::Vector3d ray(d[0], d[1], d[2]);
  const double facing = plane.normal.dot(ray);
  if (std::abs(facing) < 1e-6) return false;
  const double along = -plane.offset_m / facing;
  if (!(along > 0)) return false;
  *point = along * ray;
  return true;
}

// The cell's surface faces up or down: the ground at a wall's foot lies within relief of the wall, but it is
// not the wall. (Not "faces the plane's way": the normals at a window's frame and reveals, from neighbours
// two cells away, point anywhere, and those cells belong to the facade.)
bool FacesUp(const KnownCells& known, const cv::Vec2i& cell) {
  Eigen::Vector3f normal;
  return CellNormal(known, cell[0], cell[1], &normal) && std::abs(normal.z()) > kLevelNormalZ;
}

struct Context {
  const KnownCells& known;
  const cv::Mat& guide;
  const cv::Mat& hole;
  const AngularGrid& grid;
  const FacadeLatticeOptions& options;
  cv::Mat rim_row;  // CV_32S: for a hole cell, the row of the first cell above it outside the hole, −1 = none

  Eigen::Vector3d Point(int y, int x) const { return known.PointAt(y, x).cast<double>(); }
  // A known cell on the plane (its relief within relief_m).
  bool OnPlane(const PlaneFrame& plane, int y, int x) const {
    return known.Usable(y, x) && !hole.at<uint8_t>(y, x) &&
           std::abs(plane.SignedDistance(Point(y, x))) <= options.relief_m;
  }
  // Colour (grey levels) and relief (scaled so that relief_m weighs 255 grey levels).
  void Features(const PlaneFrame& plane, int y, int x, float* out) const {
    const int channels = guide.channels();
    const float* g = guide.ptr<float>(y) + x * channels;
    for (int k = 0; k < channels; ++k) out[k] = g[k];
    out[channels] = static_cast<float>(255.0 * plane.SignedDistance(Point(y, x)) / options.relief_m);
  }
  int feature_count() const { return guide.channels() + 1; }
  // Squared difference of the features `a` and those of cell (y, x).
  double Difference(const PlaneFrame& plane, const float* a, int y, int x) const {
    float b[kMaxFeatures];
    Features(plane, y, x, b);
    double sum = 0;
    for (int k = 0; k < feature_count(); ++k) sum += (double{a[k]} - b[k]) * (double{a[k]} - b[k]);
    return sum;
  }
  double Difference(const PlaneFrame& plane, int y0, int x0, int y1, int x1) const {
    float a[kMaxFeatures];
    Features(plane, y0, x0, a);
    return Difference(plane, a, y1, x1);
  }
  // The cell seeing the point of the plane at `point` + `shift`, when it is on the plane.
  bool Shifted(const PlaneFrame& plane, const Eigen::Vector3d& point, const Eigen::Vector3d& shift, int* y,
               int* x) const {
    return grid.CellOf(point + shift, y, x) && OnPlane(plane, *y, *x);
  }
};

// The known cells on the plane near `target_points` (where the rays of the hole cells copied from it meet it):
// at the hole's heights and a storey more, and within a few pitches of it along the plane.
std::vector<cv::Point> RegionCells(const Context& ctx, const PlaneFrame& plane,
                                   const std::vector<Eigen::Vector3d>& target_points) {
  double u_low = std::numeric_limits<double>::infinity(), u_high = -u_low;
  double v_low = u_low, v_high = -u_low;
  for (const Eigen::Vector3d& p : target_points) {
    u_low = std::min(u_low, plane.U(p));
    u_high = std::max(u_high, plane.U(p));
    v_low = std::min(v_low, plane.V(p));
    v_high = std::max(v_high, plane.V(p));
  }
  const double u_reach = 2.5 * ctx.options.max_period_m, v_reach = (v_high - v_low) + 1.0;
  std::vector<cv::Point> cells;
  const cv::Mat& range = ctx.known.range;
  for (int y = 0; y < range.rows; ++y)
    for (int x = 0; x < range.cols; ++x) {
      if (!ctx.OnPlane(plane, y, x)) continue;
      const Eigen::Vector3d p = ctx.Point(y, x);
      const double u = plane.U(p), v = plane.V(p);
      if (u < u_low - u_reach || u > u_high + u_reach || v < v_low - v_reach || v > v_high + v_reach)
        continue;
      cells.push_back({x, y});
    }
  return cells;
}

// The plane refitted by RANSAC to the region's cells (the band around the hole holds too little of a facade to
// fix its tilt: a degree off is 0.2 m four metres along, beyond the relief of a window); false when too few.
bool RefitToRegion(const Context& ctx, const std::vector<cv::Point>& cells, double inlier_m, uint64_t seed,
                   PlaneFrame* plane) {
  if (cells.size() < kMinRegionCells) return false;
  PointCloud cloud;
  const size_t every = (cells.size() + kMaxRefitPoints - 1) / kMaxRefitPoints;
  for (size_t i = 0; i < cells.size(); i += every)
    cloud.points.push_back(ctx.known.PointAt(cells[i].y, cells[i].x));
  RansacPlaneOptions ransac;
  ransac.distance_threshold_m = inlier_m;
  ransac.seed = seed;
  const PlaneFit fit = FitPlaneRansac(cloud, ransac);
  if (fit.inliers.size() < kMinRegionCells / 2) return false;
  *plane = MakeFrame(fit.normal, fit.offset_m);
  return true;
}

// The pitch along `axis` (the plane's u or v) of the plane over the region's `cells`, or 0 when it does not
// repeat.
double PlanePitch(const Context& ctx, const PlaneFrame& plane, const Eigen::Vector3d& axis,
                  const std::vector<cv::Point>& cells, double* score_out) {
  const FacadeLatticeOptions& o = ctx.options;
  if (cells.size() < kMinRegionCells) return 0;
  const size_t every =
      (cells.size() + static_cast<size_t>(o.max_samples) - 1) / static_cast<size_t>(o.max_samples);
  std::vector<cv::Point> samples;
  for (size_t i = 0; i < cells.size(); i += every) samples.push_back(cells[i]);

  // The samples' features (the same for every shift) and their variance.
  const int nf = ctx.feature_count();
  std::vector<float> features(samples.size() * static_cast<size_t>(nf));
  std::vector<double> mean(static_cast<size_t>(nf), 0.0), ranges;
  for (size_t i = 0; i < samples.size(); ++i) {
    float* f = features.data() + i * static_cast<size_t>(nf);
    ctx.Features(plane, samples[i].y, samples[i].x, f);
    for (int k = 0; k < nf; ++k) mean[static_cast<size_t>(k)] += f[k];
    ranges.push_back(ctx.known.range.at<float>(samples[i].y, samples[i].x));
  }
  for (double& m : mean) m /= static_cast<double>(samples.size());
  double variance = 0;
  for (size_t i = 0; i < features.size(); ++i) {
    const double d = features[i] - mean[i % static_cast<size_t>(nf)];
    variance += d * d;
  }
  variance /= static_cast<double>(samples.size());
  if (variance < 1.0) return 0;  // a plain wall: any shift copies the same
  std::nth_element(ranges.begin(), ranges.begin() + static_cast<long>(ranges.size() / 2), ranges.end());
  // Shifts are scored on a coarse grid (a window's score peak is as wide as the window), and the pitch found is
  // refined to half a cell's footprint.
  const double fine_m = std::max(0.5 * ranges[ranges.size() / 2] * ctx.grid.spacing_rad(), 1e-3);
  const double step_m = std::max(fine_m, kCoarseStepM);
  const int shifts = static_cast<int>(std::floor((o.max_period_m - o.min_period_m) / step_m)) + 1;
  // Sample points on the plane (the cells' points moved onto it along the normal).
  std::vector<Eigen::Vector3d> on_plane(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const Eigen::Vector3d p = ctx.Point(samples[i].y, samples[i].x);
    on_plane[i] = p - plane.SignedDistance(p) * plane.normal;
  }
  auto score_of = [&](double shift) {
    double sum = 0;
    size_t pairs = 0;
    for (size_t s = 0; s < samples.size(); ++s) {
      int y = 0, x = 0;
      if (!ctx.Shifted(plane, on_plane[s], shift * axis, &y, &x)) continue;
      sum += ctx.Difference(plane, features.data() + s * static_cast<size_t>(nf), y, x);
      ++pairs;
    }
    if (pairs < 50 || 4 * pairs < samples.size()) return -std::numeric_limits<double>::infinity();
    return 1.0 - sum / static_cast<double>(pairs) / (2.0 * variance);
  };
  std::vector<double> score(static_cast<size_t>(shifts));
  ParallelFor(shifts, [&](int64_t i) {
    score[static_cast<size_t>(i)] = score_of(o.min_period_m + static_cast<double>(i) * step_m);
  });
  // Only peaks count: a plain wall with a few windows scores high at the shortest shifts, which only say that
  // the wall goes on. A peak also stands out from the valley before it: a plain wall's colour and shading vary
  // slowly, so every shift scores about the same, noise making small peaks anywhere.
  auto peak_at = [&](int i) {
    if (i <= 0 || i + 1 >= shifts || score[static_cast<size_t>(i)] < score[static_cast<size_t>(i - 1)] ||
        score[static_cast<size_t>(i)] < score[static_cast<size_t>(i + 1)])
      return false;
    const double valley = *std::min_element(score.begin(), score.begin() + i);
    return score[static_cast<size_t>(i)] - valley >= kMinProminence;
  };
  auto best_peak = [&](int first, int last) {
    int best = -1;
    for (int i = std::max(first, 1); i <= std::min(last, shifts - 2); ++i)
      if (peak_at(i) && (best < 0 || score[static_cast<size_t>(i)] > score[static_cast<size_t>(best)]))
        best = i;
    return best;
  };
  // The coarse peak refined on the fine grid within a coarse step either side.
  auto refined = [&](int coarse) {
    const double centre = o.min_period_m + coarse * step_m;
    const int reach = static_cast<int>(std::ceil(step_m / fine_m));
    std::vector<double> fine(static_cast<size_t>(2 * reach + 1));
    ParallelFor(2 * reach + 1, [&](int64_t k) {
      fine[static_cast<size_t>(k)] = score_of(centre + static_cast<double>(k - reach) * fine_m);
    });
    const auto top = std::max_element(fine.begin(), fine.end());
    *score_out = *top;
    return centre + static_cast<double>((top - fine.begin()) - reach) * fine_m;
  };
  const int best = best_peak(0, shifts - 1);
  if (best < 0 || !(score[static_cast<size_t>(best)] >= o.min_score)) return 0;
  // The best shift may be a multiple of the pitch (a door or a car spoils one shift more than another): the
  // pitch is the shortest whole fraction of it that still repeats.
  const double best_shift = o.min_period_m + best * step_m;
  for (int n = kMaxDivisor; n >= 2; --n) {
    const double shift = best_shift / n;
    const double reach = std::max(2.0 * step_m, kDivisorReach * shift);
    const int peak = best_peak(static_cast<int>(std::ceil((shift - reach - o.min_period_m) / step_m)),
                               static_cast<int>(std::floor((shift + reach - o.min_period_m) / step_m)));
    if (peak >= 0 && score[static_cast<size_t>(peak)] >= o.min_score) return refined(peak);
  }
  return refined(best);
}

// The cells that see `point` shifted by ±1 .. ±max_translates pitches along u and storeys along v (pitches 0 =
// no repetition along that axis), kVoters at most per axis, nearest first.
std::vector<cv::Vec2i> Translates(const Context& ctx, const PlaneFrame& plane, const Eigen::Vector3d& point,
                                  double pitch_m, double storey_m) {
  std::vector<cv::Vec2i> found;
  for (const auto& [axis, step_m] : {std::pair(plane.u_axis, pitch_m), std::pair(plane.v_axis, storey_m)}) {
    if (step_m <= 0) continue;
    const size_t before = found.size();
    for (int k = 1; k <= ctx.options.max_translates && found.size() - before < kVoters; ++k)
      for (const int side : {1, -1}) {
        int y = 0, x = 0;
        if (found.size() - before < kVoters && ctx.Shifted(plane, point, side * k * step_m * axis, &y, &x))
          found.push_back(cv::Vec2i(y, x));
      }
  }
  return found;
}

// The index of the cell that differs least from all the others (the earliest on ties).
size_t Medoid(const Context& ctx, const PlaneFrame& plane, const std::vector<cv::Vec2i>& cells) {
  size_t best = 0;
  double best_disagreement = std::numeric_limits<double>::infinity();
  for (size_t a = 0; a < cells.size(); ++a) {
    double disagreement = 0;
    for (size_t b = 0; b < cells.size(); ++b)
      if (a != b) disagreement += ctx.Difference(plane, cells[a][0], cells[a][1], cells[b][0], cells[b][1]);
    if (disagreement < best_disagreement) best_disagreement = disagreement, best = a;
  }
  return best;
}

// A known cell on the plane that differs from what its translates agree on, and from the cells around that
// one (a pitch lands a cell or two off on thin frame bars).
bool Exceptional(const Context& ctx, const PlaneFrame& plane, int y, int x, double pitch_m, double storey_m) {
  const Eigen::Vector3d p = ctx.Point(y, x);
  const std::vector<cv::Vec2i> translates =
      Translates(ctx, plane, p - plane.SignedDistance(p) * plane.normal, pitch_m, storey_m);
  if (translates.empty()) return false;
  const cv::Vec2i rule = translates[Medoid(ctx, plane, translates)];
  const double limit = kExceptionGrey * kExceptionGrey * ctx.feature_count();
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (ctx.OnPlane(plane, rule[0] + dy, rule[1] + dx) &&
          ctx.Difference(plane, y, x, rule[0] + dy, rule[1] + dx) <= limit)
        return false;
  return true;
}

// The first known cell on the plane straight above `point`, through the hole. Up an upright plane is up its
// image column (a vertical line of the plane keeps one azimuth), so the hole's rim above each cell is looked up,
// not climbed to. False when the cell above the hole is not on the plane (the sky, a balcony) or there is none.
bool RimAbove(const Context& ctx, const PlaneFrame& plane, const Eigen::Vector3d& point, cv::Vec2i* rim) {
  int y = 0, x = 0;
  if (!ctx.grid.CellOf(point, &y, &x)) return false;
  const int row = ctx.hole.at<uint8_t>(y, x) ? ctx.rim_row.at<int32_t>(y, x) : y;
  if (row < 0 || !ctx.OnPlane(plane, row, x)) return false;
  *rim = cv::Vec2i(row, x);
  return true;
}

// Whether a rim cell (the first cell above the hole in its column) is an exception, cached: every hole cell
// of a column asks about the same one. CV_8S per cell: −1 unknown, 0 no, 1 yes; filled before the parallel
// loop that reads it.
class RimExceptions {
 public:
  RimExceptions(const Context& ctx, const PlaneFrame& plane, double pitch_m, double storey_m) {
    exceptional_ = cv::Mat(ctx.hole.size(), CV_8S, cv::Scalar(-1));
    std::vector<cv::Point> rims;
    for (int y = 0; y + 1 < ctx.hole.rows; ++y)
      for (int x = 0; x < ctx.hole.cols; ++x)
        if (!ctx.hole.at<uint8_t>(y, x) && ctx.hole.at<uint8_t>(y + 1, x) && ctx.OnPlane(plane, y, x))
          rims.push_back({x, y});
    std::vector<int8_t> answer(rims.size(), 0);
    ParallelFor(static_cast<int64_t>(rims.size()), [&](int64_t i) {
      const cv::Point r = rims[static_cast<size_t>(i)];
      answer[static_cast<size_t>(i)] = Exceptional(ctx, plane, r.y, r.x, pitch_m, storey_m) ? 1 : 0;
    });
    for (size_t i = 0; i < rims.size(); ++i) exceptional_.at<int8_t>(rims[i]) = answer[i];
  }
  bool At(const cv::Vec2i& cell) const { return exceptional_.at<int8_t>(cell[0], cell[1]) == 1; }

 private:
  cv::Mat exceptional_;
};

// Whether what the hole hides above `point` is an exception to the lattice, and then the rim cell to extrude:
// the rim above the point, and the rim above the point kExceptionReachM along the plane to one side, both
// differ from what their translates agree on (a door's top where the other bays show a window's; not a
// window's mullion or jamb, which a pitch may land a cell beside).
bool ExceptionAbove(const Context& ctx, const PlaneFrame& plane, const RimExceptions& exceptions,
                    const Eigen::Vector3d& point, cv::Vec2i* rim) {
  if (!RimAbove(ctx, plane, point, rim) || !exceptions.At(*rim)) return false;
  for (const double side : {-kExceptionReachM, kExceptionReachM}) {
    cv::Vec2i beside;
    if (RimAbove(ctx, plane, point + side * plane.u_axis, &beside) && exceptions.At(beside)) return true;
  }
  return false;
}

// Step 3 of the header for one periodic plane (pitches 0 = no repetition along that axis).
int64_t CopyAlongLattice(const Context& ctx, const PlaneFrame& plane, double pitch_m, double storey_m,
                         const std::vector<cv::Point>& targets, cv::Mat* source, cv::Mat* relief_range) {
  int64_t copied = 0;
  std::vector<cv::Vec2i> chosen(targets.size(), cv::Vec2i(-1, -1));
  std::vector<float> range(targets.size(), 0.0f);
  const RimExceptions exceptions(ctx, plane, pitch_m, storey_m);
  ParallelFor(static_cast<int64_t>(targets.size()), [&](int64_t i) {
    const cv::Point t = targets[static_cast<size_t>(i)];
    Eigen::Vector3d point;
    if (!RayPoint(ctx.known.direction, plane, t.y, t.x, &point)) return;
    cv::Vec2i from;
    if (!ExceptionAbove(ctx, plane, exceptions, point, &from)) {
      std::vector<cv::Vec2i> found = Translates(ctx, plane, point, pitch_m, storey_m);
      if (found.empty()) return;
      // The patch fill's own choice votes too (last, so that it wins no tie): a shift that lands on the one
      // door of a facade, with only the wall one pitch further to vote against it, is outvoted.
      found.push_back(source->at<cv::Vec2i>(t.y, t.x));
      from = found[Medoid(ctx, plane, found)];
    }
    chosen[static_cast<size_t>(i)] = from;
    // Along the ray to the plane moved by the source's relief (n · x + offset − relief = 0).
    const double relief = plane.SignedDistance(ctx.Point(from[0], from[1]));
    range[static_cast<size_t>(i)] =
        static_cast<float>(point.norm() * (plane.offset_m - relief) / plane.offset_m);
  });
  for (size_t i = 0; i < targets.size(); ++i) {
    cv::Vec2i& from = source->at<cv::Vec2i>(targets[i].y, targets[i].x);
    if (chosen[i][0] < 0) continue;
    relief_range->at<float>(targets[i].y, targets[i].x) = range[i];
    if (chosen[i] == from) continue;
    from = chosen[i];
    ++copied;
  }
  return copied;
}

}  // namespace

FacadeLatticeReport RefineSourcesByLattice(const cv::Mat& range, const cv::Mat& known_valid,
                                           const cv::Mat& direction, const cv::Mat& guide,
                                           const cv::Mat& hole, const ScanGrid& grid,
                                           const FillPlaneOptions& planes,
                                           const FacadeLatticeOptions& options, uint64_t seed,
                                           cv::Mat* source, cv::Mat* relief_range) {
  options.Check();
  FacadeLatticeReport report;
  *relief_range = cv::Mat::zeros(hole.size(), CV_32F);
  if (!options.enabled || source->empty()) return report;
  AngularGrid angular;
  if (!angular.Init(grid, hole.rows, hole.cols)) return report;
  const KnownCells known{range, known_valid, direction};
  Context ctx{known, guide, hole, angular, options, cv::Mat(hole.size(), CV_32S, cv::Scalar(-1))};
  for (int x = 0; x < hole.cols; ++x) {
    int above = -1;  // the last row outside the hole, going down the column
    for (int y = 0; y < hole.rows; ++y) {
      if (!hole.at<uint8_t>(y, x))
        above = y;
      else
        ctx.rim_row.at<int32_t>(y, x) = above;
    }
  }
  cv::Mat part_id, stats, centroids;
  const int part_count = cv::connectedComponentsWithStats(hole != 0, part_id, stats, centroids, 8, CV_32S);
  for (int id = 1; id < part_count; ++id) {
    const cv::Rect box(stats.at<int>(id, cv::CC_STAT_LEFT), stats.at<int>(id, cv::CC_STAT_TOP),
                       stats.at<int>(id, cv::CC_STAT_WIDTH), stats.at<int>(id, cv::CC_STAT_HEIGHT));
    double threshold_m = 0;
    const std::vector<SeenPlane> seen =
        BandPlanes(known, part_id, id, box, stats.at<int>(id, cv::CC_STAT_AREA), planes,
                   seed + static_cast<uint64_t>(id), &threshold_m);
    for (const SeenPlane& s : seen) {
      if (std::abs(s.normal.z()) > kUprightNormalZ) continue;
      // The part's cells that the patch fill copied from the plane, and where their rays meet it.
      std::vector<cv::Point> targets;
      std::vector<Eigen::Vector3d> target_points;
      auto find_targets = [&](const PlaneFrame& plane) {
        targets.clear();
        target_points.clear();
        for (int y = box.y; y < box.y + box.height; ++y)
          for (int x = box.x; x < box.x + box.width; ++x) {
            if (part_id.at<int32_t>(y, x) != id) continue;
            const cv::Vec2i from = source->at<cv::Vec2i>(y, x);
            Eigen::Vector3d point;
            if (from[0] < 0 || !ctx.OnPlane(plane, from[0], from[1]) || FacesUp(known, from) ||
                !RayPoint(direction, plane, y, x, &point))
              continue;
            targets.push_back({x, y});
            target_points.push_back(point);
          }
      };
      PlaneFrame plane = MakeFrame(s.normal, s.offset_m);
      find_targets(plane);
      if (targets.empty() ||
          !RefitToRegion(ctx, RegionCells(ctx, plane, target_points), threshold_m, seed, &plane))
        continue;
      find_targets(plane);
      if (targets.empty()) continue;
      const std::vector<cv::Point> region = RegionCells(ctx, plane, target_points);
      double score = 0, storey_score = 0;
      const double pitch = PlanePitch(ctx, plane, plane.u_axis, region, &score);
      const double storey = PlanePitch(ctx, plane, plane.v_axis, region, &storey_score);
      if (pitch <= 0 && storey <= 0) continue;
      report.pitches_m.push_back(pitch);
      report.storeys_m.push_back(storey);
      report.cells += CopyAlongLattice(ctx, plane, pitch, storey, targets, source, relief_range);
    }
  }
  return report;
}

}  // namespace fill_internal
}  // namespace lidarshop
