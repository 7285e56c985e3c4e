#include "lidarshop/recolor/recolor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/recolor/distance_raster.h"
#include "lidarshop/recolor/silhouette_skirt.h"
#include "lidarshop/recolor/visibility.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void RecolorOptions::Check() const { Validate(*this); }

RecolorSummary SummarizeRecolor(const RecolorResult& result, const std::optional<ResectionSummary>& resection,
                                const std::optional<AutoResectionSummary>& auto_resection) {
  RecolorSummary summary;
  summary.returns = result.returns;
  summary.recolored = result.recolored_count;
  summary.outside_image = result.outside_image;
  summary.hidden = result.hidden;
  summary.uncertain = result.uncertain;
  summary.edge_margin_px = result.edge_margin_px;
  if (std::isfinite(result.disagreement)) summary.disagreement = result.disagreement;
  if (resection) summary.warnings = resection->warnings;
  if (auto_resection) summary.warnings = auto_resection->warnings;
  summary.warnings.insert(summary.warnings.end(), result.warnings.begin(), result.warnings.end());
  summary.resection = resection;
  summary.auto_resection = auto_resection;
  return summary;
}

std::string RecolorResult::Summary() const {
  return fmt::format(
      "{} of {} points recoloured; {} outside the photo, {} hidden from the camera{}{}", recolored_count,
      returns, outside_image, hidden,
      uncertain > 0 ? fmt::format(", {} kept near occluding edges (uncertain, {:.1f} px margin)", uncertain,
                                  edge_margin_px)
                    : "",
      std::isnan(disagreement)
          ? ""
          : fmt::format("; {:.0f} % disagree with the scan's own brightness", 100 * disagreement));
}

namespace {

// Blends up to four photo pixels (`weights` sum to > 0): bilinear, unless they differ by more than
// `max_blend_levels` in a channel, then the colour of the one with the largest weight.
cv::Vec3b BlendUnlessEdge(const cv::Vec3b (&values)[4], const double (&weights)[4], int max_blend_levels) {
  double sum[3] = {0, 0, 0}, weight = 0;
  int heaviest = -1;
  cv::Vec3b low(255, 255, 255), high(0, 0, 0);
  for (int k = 0; k < 4; ++k) {
    if (weights[k] <= 0) continue;
    if (heaviest < 0 || weights[k] > weights[heaviest]) heaviest = k;
    for (int c = 0; c < 3; ++c) {
      sum[c] += weights[k] * values[k][c];
      low[c] = std::min(low[c], values[k][c]);
      high[c] = std::max(high[c], values[k][c]);
    }
    weight += weights[k];
  }
  for (int c = 0; c < 3; ++c)
    if (high[c] - low[c] > max_blend_levels) return values[heaviest];
  cv::Vec3b out;
  for (int c = 0; c < 3; ++c) out[c] = cv::saturate_cast<uint8_t>(sum[c] / weight);
  return out;
}

}  // namespace

cv::Vec3b SamplePhoto(const cv::Mat& photo, const Eigen::Vector2d& pixel_px, int max_blend_levels) {
  // Array coordinates: the centre of pixel (0, 0) is at (0, 0).
  const double x = std::clamp(pixel_px.x() - 0.5, 0.0, photo.cols - 1.0);
  const double y = std::clamp(pixel_px.y() - 0.5, 0.0, photo.rows - 1.0);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, photo.cols - 1), y1 = std::min(y0 + 1, photo.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const cv::Vec3b values[4] = {photo.at<cv::Vec3b>(y0, x0), photo.at<cv::Vec3b>(y0, x1),
                               photo.at<cv::Vec3b>(y1, x0), photo.at<cv::Vec3b>(y1, x1)};
  const double weights[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};  // sum to 1
  return BlendUnlessEdge(values, weights, max_blend_levels);
}

namespace {

// Distance from the camera centre to the first surface of `scene` through each z-buffer pixel (+inf: none);
// `back_facing` (CV_8U) marks pixels whose first surface turns its back to the camera (the scan mesh faces
// the scanner: the camera then sees the side of that surface the scanner did not see).
// |difference| of two distances, +inf when either is infinite.
float Step(float a, float b) { return std::isfinite(a) && std::isfinite(b) ? std::abs(a - b) : INFINITY; }

// One-sided (smaller) depth slope per z-buffer pixel, x plus y, metres per pixel.
float Slope(const cv::Mat& d, int r, int c) {
  const float here = d.at<float>(r, c);
  const float left = c > 0 ? Step(here, d.at<float>(r, c - 1)) : INFINITY;
  const float right = c + 1 < d.cols ? Step(here, d.at<float>(r, c + 1)) : INFINITY;
  const float up = r > 0 ? Step(here, d.at<float>(r - 1, c)) : INFINITY;
  const float down = r + 1 < d.rows ? Step(here, d.at<float>(r + 1, c)) : INFINITY;
  const float sx = std::min(left, right), sy = std::min(up, down);
  return (std::isfinite(sx) ? sx : 0.0f) + (std::isfinite(sy) ? sy : 0.0f);
}

// The scan's angular step, radians: the larger of the median angles between horizontally and between
// vertically adjacent returns (every 4th row and column, enough for a median).
double AngularStepRad(const Scan& scan) {
  std::vector<double> across, down;
  const auto direction = [&](int r, int c) {
    const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
    return Eigen::Vector3d(p[0], p[1], p[2]).normalized();
  };
  for (int r = 0; r + 1 < scan.rows; r += 4) {
    for (int c = 0; c + 1 < scan.cols; c += 4) {
      if (!scan.valid.at<uint8_t>(r, c)) continue;
      const Eigen::Vector3d here = direction(r, c);
      if (scan.valid.at<uint8_t>(r, c + 1))
        across.push_back(std::acos(std::clamp(here.dot(direction(r, c + 1)), -1.0, 1.0)));
      if (scan.valid.at<uint8_t>(r + 1, c))
        down.push_back(std::acos(std::clamp(here.dot(direction(r + 1, c)), -1.0, 1.0)));
    }
  }
  const auto median = [](std::vector<double>& v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  return std::max(median(across), median(down));
}

// The photo's colour at `pixel_px`, bilinear over the pixels whose z-buffer distance is within `allowed` of
// `distance` (no blend across a depth edge, nor across a colour edge: BlendUnlessEdge); the nearest pixel's
// colour when none of the four agrees.
cv::Vec3b SampleAgreeing(const cv::Mat& photo, const cv::Mat& distance_buffer, double sx, double sy,
                         const Eigen::Vector2d& pixel_px, double distance, double allowed,
                         int max_blend_levels) {
  const double x = std::clamp(pixel_px.x() - 0.5, 0.0, photo.cols - 1.0);
  const double y = std::clamp(pixel_px.y() - 0.5, 0.0, photo.rows - 1.0);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int xs[2] = {x0, std::min(x0 + 1, photo.cols - 1)}, ys[2] = {y0, std::min(y0 + 1, photo.rows - 1)};
  const double wx[2] = {1 - (x - x0), x - x0}, wy[2] = {1 - (y - y0), y - y0};
  cv::Vec3b values[4];
  double weights[4], weight = 0;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const int k = 2 * j + i;
      values[k] = photo.at<cv::Vec3b>(ys[j], xs[i]);
      const int zr = std::min(static_cast<int>((ys[j] + 0.5) * sy), distance_buffer.rows - 1);
      const int zc = std::min(static_cast<int>((xs[i] + 0.5) * sx), distance_buffer.cols - 1);
      const bool agrees = std::abs(distance_buffer.at<float>(zr, zc) - distance) <= allowed;
      weights[k] = agrees ? wx[i] * wy[j] : 0.0;
      weight += weights[k];
    }
  }
  if (weight <= 1e-9) {
    const int nx = std::clamp(static_cast<int>(pixel_px.x()), 0, photo.cols - 1);
    const int ny = std::clamp(static_cast<int>(pixel_px.y()), 0, photo.rows - 1);
    return photo.at<cv::Vec3b>(ny, nx);
  }
  return BlendUnlessEdge(values, weights, max_blend_levels);
}

}  // namespace

namespace recolor_internal {

OcclusionScene BuildOcclusionScene(const Scan& scan, const RecolorOptions& options) {
  OcclusionScene scene;
  ScanMeshOptions mesh_options;
  mesh_options.max_range_jump_ratio = options.max_range_jump_ratio;
  mesh_options.world_frame = true;
  // The mesh and the skirts are independent (each parallel inside, serial in parts): built side by side.
  ParallelFor(2, [&](int64_t part) {
    if (part == 0) {
      scene.mesh = ScanToMesh(scan, mesh_options);
    } else if (options.silhouette_skirts) {
      SilhouetteSkirtOptions skirt_options;
      skirt_options.max_range_jump_ratio = options.max_range_jump_ratio;
      skirt_options.depth_m = options.skirt_depth_m;
      skirt_options.depth_per_width = options.skirt_depth_per_width;
      scene.skirts = SilhouetteSkirts(scan, skirt_options);
    }
  });
  if (options.visibility == VisibilityMethod::kZBuffer) {
    scene.mesh_blocks = TriangleBlockBoxes(scene.mesh);
    scene.skirt_blocks = TriangleBlockBoxes(scene.skirts);
  }
  scene.cells = CellBoxesOf(scan);
  if (options.visibility == VisibilityMethod::kSegment) {
    scene.segments = std::make_unique<RaycastScene>();
    if (!scene.mesh.empty()) scene.segments->AddMesh(scene.mesh, 0);
    if (!scene.skirts.empty()) scene.segments->AddMesh(scene.skirts, 1);
    scene.segments->Commit();
  }
  return scene;
}

Visibility VisibleCells(const Scan& scan, const OcclusionScene& scene, const Camera& camera,
                        const RecolorOptions& options, bool by_row) {
  Visibility visibility;
  const Eigen::Vector3d center = camera.center_in_world();
  const Eigen::Matrix3d rotation = scan.world_from_scanner.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = scan.world_from_scanner.topRightCorner<3, 1>();
  const auto tolerance = [&](double distance) {
    return options.depth_tolerance_m + options.relative_depth_tolerance * distance;
  };

  // Calls in_view(cell, pixel, point_in_world) for every valid cell of row r in front of the camera that
  // projects inside the photo, in column order; counts the row's returns and the cells outside. Row segments
  // whose box lies outside the image's view planes are outside the image whole (view_cull.h).
  const ViewPlanes planes = ImageViewPlanes(camera);
  const CellBoxes& boxes = scene.cells;
  const bool by_segment =
      boxes.segments > 0 && boxes.valid.size() == static_cast<size_t>(scan.rows) * boxes.segments;
  std::vector<int64_t> row_returns(scan.rows, 0), row_outside(scan.rows, 0);
  const auto for_each_in_view = [&](int r, const auto& in_view) {
    const int segments = by_segment ? boxes.segments : 1;
    for (int s = 0; s < segments; ++s) {
      const int c_begin = by_segment ? s * boxes.segment_cols : 0;
      const int c_end = by_segment ? std::min(scan.cols, c_begin + boxes.segment_cols) : scan.cols;
      if (by_segment) {
        const size_t box = static_cast<size_t>(r) * boxes.segments + s;
        if (boxes.valid[box] == 0) continue;
        if (planes.count > 0 && planes.Outside(boxes.boxes[box])) {
          row_returns[r] += boxes.valid[box];
          row_outside[r] += boxes.valid[box];
          continue;
        }
      }
      const uint8_t* valid = scan.valid.ptr<uint8_t>(r);
      const cv::Vec3f* points = scan.point.ptr<cv::Vec3f>(r);
      for (int c = c_begin; c < c_end; ++c) {
        if (!valid[c]) continue;
        ++row_returns[r];
        const cv::Vec3f& p = points[c];
        const Eigen::Vector3d point_in_world = rotation * Eigen::Vector3d(p[0], p[1], p[2]) + translation;
        Eigen::Vector2d pixel;
        if (!ProjectWorldPoint(camera, point_in_world, &pixel) || !InsideImage(camera, pixel)) {
          ++row_outside[r];
          continue;
        }
        in_view(static_cast<int64_t>(r) * scan.cols + c, pixel, point_in_world);
      }
    }
  };
  // Rows in parallel, each into its own lists, joined in row order (the same on any thread count).
  std::vector<std::vector<SeenCell>> row_seen(scan.rows);
  std::vector<std::vector<int64_t>> row_uncertain(scan.rows);
  std::vector<int64_t> row_hidden(scan.rows, 0);

  if (options.visibility == VisibilityMethod::kSegment) {
    struct Candidate {
      int64_t cell;
      Eigen::Vector2d pixel;
      Eigen::Vector3d point_in_world;
    };
    std::vector<std::vector<Candidate>> row_candidates(scan.rows);
    ParallelFor(scan.rows, [&](int64_t row) {
      for_each_in_view(static_cast<int>(row), [&](int64_t cell, const Eigen::Vector2d& pixel,
                                                  const Eigen::Vector3d& point_in_world) {
        row_candidates[row].push_back({cell, pixel, point_in_world});
      });
    });
    std::vector<Candidate> candidates;
    for (auto& row : row_candidates) {
      candidates.insert(candidates.end(), row.begin(), row.end());
      std::vector<Candidate>().swap(row);
    }
    std::vector<uint8_t> hidden(candidates.size(), 0);
    std::vector<Ray> rays(candidates.size());
    for (size_t i = 0; i < candidates.size(); ++i) {
      const Eigen::Vector3d segment = candidates[i].point_in_world - center;
      const double distance = segment.norm();
      rays[i].origin = center.cast<float>();
      rays[i].direction = segment.cast<float>();
      rays[i].t_far = static_cast<float>(std::max(0.0, 1.0 - tolerance(distance) / distance));
    }
    scene.segments->Occluded(rays, hidden);
    for (size_t i = 0; i < candidates.size(); ++i) {
      const int64_t row = candidates[i].cell / scan.cols;
      if (hidden[i]) {
        ++row_hidden[row];
        continue;
      }
      row_seen[row].push_back({candidates[i].cell, candidates[i].pixel,
                               (candidates[i].point_in_world - center).norm(),
                               std::numeric_limits<double>::infinity()});
    }
  } else {
    // The z-buffer first, then every cell projected and tested in one pass (no list of candidates).
    const auto zbuffer_start = std::chrono::steady_clock::now();
    const DistanceBuffer buffer =
        RasterDistanceBuffer(scene.mesh, scene.skirts, camera, options.zbuffer_scale, RasterOptions(),
                             {scene.mesh_blocks.empty() ? nullptr : &scene.mesh_blocks,
                              scene.skirt_blocks.empty() ? nullptr : &scene.skirt_blocks});
    const cv::Mat& distance_buffer = buffer.distance;
    const cv::Mat& back_facing = buffer.back_facing;
    cv::Mat nearest = distance_buffer;
    const int m = options.silhouette_margin_px;
    if (m > 0) cv::erode(distance_buffer, nearest, cv::Mat::ones(2 * m + 1, 2 * m + 1, CV_8U));
    const double sx = static_cast<double>(distance_buffer.cols) / camera.width_px();
    const double sy = static_cast<double>(distance_buffer.rows) / camera.height_px();
    visibility.distance_buffer = distance_buffer;
    visibility.buffer_per_photo_px = Eigen::Vector2d(sx, sy);
    // The edge guard's window: the camera's uncertainty and one scan step, in z-buffer pixels.
    int guard = 0;
    cv::Mat guard_nearest;
    if (options.edge_guard) {
      visibility.edge_margin_px =
          options.camera_uncertainty_px + AngularStepRad(scan) / camera.PixelAngleRad();
      guard = std::max(m, static_cast<int>(std::ceil(visibility.edge_margin_px * std::max(sx, sy))));
      cv::erode(distance_buffer, guard_nearest, cv::Mat::ones(2 * guard + 1, 2 * guard + 1, CV_8U));
    }
    visibility.zbuffer_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - zbuffer_start).count();
    ParallelFor(scan.rows, [&](int64_t row) {
      for_each_in_view(static_cast<int>(row), [&](int64_t cell, const Eigen::Vector2d& pixel,
                                                  const Eigen::Vector3d& point_in_world) {
        const int zr = std::min(static_cast<int>(pixel.y() * sy), distance_buffer.rows - 1);
        const int zc = std::min(static_cast<int>(pixel.x() * sx), distance_buffer.cols - 1);
        const double distance = (point_in_world - center).norm();
        const float slope = Slope(distance_buffer, zr, zc);
        const double allowed = tolerance(distance) + m * slope;
        if (nearest.at<float>(zr, zc) < distance - allowed || back_facing.at<uint8_t>(zr, zc) != 0) {
          ++row_hidden[row];
          return;
        }
        // A surface clearly nearer within the guard's window: the point lies by an occluding edge, where
        // the camera's error can show the occluder's colour; it keeps its own (uncertain).
        if (guard > 0 && guard_nearest.at<float>(zr, zc) <
                             distance - tolerance(distance) - options.edge_min_jump_m - guard * slope) {
          row_uncertain[row].push_back(cell);
          return;
        }
        row_seen[row].push_back({cell, pixel, distance, tolerance(distance) + slope});
      });
    });
  }

  size_t seen = 0, uncertain = 0;
  for (int r = 0; r < scan.rows; ++r) seen += row_seen[r].size(), uncertain += row_uncertain[r].size();
  if (!by_row) visibility.seen.reserve(seen);
  visibility.uncertain.reserve(uncertain);
  for (int r = 0; r < scan.rows; ++r) {
    visibility.returns += row_returns[r];
    visibility.outside_image += row_outside[r];
    visibility.hidden += row_hidden[r];
    visibility.uncertain.insert(visibility.uncertain.end(), row_uncertain[r].begin(), row_uncertain[r].end());
    if (by_row) continue;
    visibility.seen.insert(visibility.seen.end(), row_seen[r].begin(), row_seen[r].end());
    std::vector<SeenCell>().swap(row_seen[r]);
  }
  if (by_row) visibility.row_seen = std::move(row_seen);
  return visibility;
}

}  // namespace recolor_internal

RecolorResult RecolorScan(const Scan& scan, const cv::Mat& photo, const PinholeCamera& camera,
                          const RecolorOptions& options) {
  options.Check();
  camera.Check("camera");
  if (photo.type() != CV_8UC3) ThrowInputError("photo", "", "", "expected an 8-bit RGB image");
  if (photo.cols != camera.width_px || photo.rows != camera.height_px)
    ThrowInputError("photo", "", "",
                    fmt::format("the photo is {} x {} pixels but the camera is {} x {}", photo.cols,
                                photo.rows, camera.width_px, camera.height_px));
  CheckScan(scan);

  RecolorResult result;
  result.scan = Clone(scan);
  Scan& out = result.scan;
  if (!out.has_color() && !out.has_intensity()) {
    out.color = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));  // black where not recoloured
  } else if (!out.has_color()) {
    out.color.create(scan.rows, scan.cols, CV_8UC3);
    for (int r = 0; r < scan.rows; ++r) {
      for (int c = 0; c < scan.cols; ++c) {
        const uint8_t grey = cv::saturate_cast<uint8_t>(255.0f * scan.intensity.at<float>(r, c));
        out.color.at<cv::Vec3b>(r, c) = cv::Vec3b(grey, grey, grey);
      }
    }
  }
  result.recolored = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
  result.uncertain_mask = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);

  const Camera model = CameraFromPinhole(camera);
  const recolor_internal::OcclusionScene occlusion = recolor_internal::BuildOcclusionScene(scan, options);
  const recolor_internal::Visibility visibility =
      recolor_internal::VisibleCells(scan, occlusion, model, options);
  result.returns = visibility.returns;
  result.outside_image = visibility.outside_image;
  result.hidden = visibility.hidden;
  result.edge_margin_px = visibility.edge_margin_px;
  for (const int64_t cell : visibility.uncertain) {
    ++result.uncertain;
    result.uncertain_mask.at<uint8_t>(static_cast<int>(cell / scan.cols),
                                      static_cast<int>(cell % scan.cols)) = 255;
  }
  for (const recolor_internal::SeenCell& seen : visibility.seen) {
    const int r = static_cast<int>(seen.cell / scan.cols), c = static_cast<int>(seen.cell % scan.cols);
    // No blend across a depth edge: only the photo pixels at the point's own depth (z-buffer visibility).
    out.color.at<cv::Vec3b>(r, c) =
        visibility.distance_buffer.empty()
            ? SamplePhoto(photo, seen.pixel, options.max_blend_levels)
            : SampleAgreeing(photo, visibility.distance_buffer, visibility.buffer_per_photo_px.x(),
                             visibility.buffer_per_photo_px.y(), seen.pixel, seen.distance_m, seen.agree_m,
                             options.max_blend_levels);
    result.recolored.at<uint8_t>(r, c) = 255;
    ++result.recolored_count;
  }
  result.disagreement = RecolorDisagreement(scan, out.color, result.recolored);
  if (result.disagreement > kRecolorDisagreementLimit) {
    result.warnings.push_back(fmt::format(
        "the photo's colours disagree with the scan's own {} on {:.0f} % of the {} recoloured points (more "
        "than {:.0f} %; unrelated values disagree on {:.0f} %): the camera is probably wrong (check the "
        "resection's pairs and RMS)",
        scan.has_color() ? "colours" : "intensity", 100 * result.disagreement, result.recolored_count,
        100 * kRecolorDisagreementLimit, 100 * (1 - (1 - kRecolorRankGap) * (1 - kRecolorRankGap))));
  }
  return result;
}

namespace {

// Quantile ranks in [0, 1] of `values`, ties sharing their mean rank.
std::vector<double> Ranks(const std::vector<float>& values) {
  std::vector<int64_t> order(values.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int64_t>(i);
  std::sort(order.begin(), order.end(), [&](int64_t a, int64_t b) { return values[a] < values[b]; });
  std::vector<double> ranks(values.size());
  const double scale = values.size() > 1 ? 1.0 / static_cast<double>(values.size() - 1) : 0.0;
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j + 1 < order.size() && values[order[j + 1]] == values[order[i]]) ++j;
    const double rank = 0.5 * static_cast<double>(i + j) * scale;
    for (size_t k = i; k <= j; ++k) ranks[order[k]] = rank;
    i = j + 1;
  }
  return ranks;
}

float Luma(const cv::Vec3b& rgb) { return 0.299f * rgb[0] + 0.587f * rgb[1] + 0.114f * rgb[2]; }

}  // namespace

double RecolorDisagreement(const Scan& before, const cv::Mat& after_color, const cv::Mat& recolored,
                           int64_t max_points) {
  const double none = std::numeric_limits<double>::quiet_NaN();
  if (!before.has_color() && !before.has_intensity()) return none;
  const int64_t count = cv::countNonZero(recolored);
  if (count == 0) return none;
  const int64_t stride = std::max<int64_t>(1, (count + max_points - 1) / std::max<int64_t>(1, max_points));
  std::vector<float> own, photo;
  int64_t seen = 0;
  for (int r = 0; r < recolored.rows; ++r) {
    for (int c = 0; c < recolored.cols; ++c) {
      if (!recolored.at<uint8_t>(r, c) || seen++ % stride != 0) continue;
      own.push_back(before.has_color() ? Luma(before.color.at<cv::Vec3b>(r, c))
                                       : before.intensity.at<float>(r, c));
      photo.push_back(Luma(after_color.at<cv::Vec3b>(r, c)));
    }
  }
  const std::vector<double> own_rank = Ranks(own), photo_rank = Ranks(photo);
  int64_t disagree = 0;
  for (size_t i = 0; i < own.size(); ++i) disagree += std::abs(own_rank[i] - photo_rank[i]) > kRecolorRankGap;
  return static_cast<double>(disagree) / static_cast<double>(own.size());
}

}  // namespace lidarshop
