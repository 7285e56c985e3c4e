#include "lidarshop/verify/sweep.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/verify/sweep_bound.h"

namespace lidarshop {
namespace {

std::vector<double> Range(double lo, double hi, double step) {
  std::vector<double> values;
  const int64_t count = static_cast<int64_t>(std::floor((hi - lo) / step + 1e-9)) + 1;
  for (int64_t i = 0; i < count; ++i) values.push_back(lo + step * i);
  return values;
}

std::string Field(double value, const char* format = "{:.6g}") {
  return std::isnan(value) ? std::string() : fmt::format(fmt::runtime(format), value);
}

double Score(const VerifyResult& r) { return r.has_comparable_pairs ? r.consistency + r.confidence : 0.0; }

// Coordinate ascent from the best grid poses (see SweepOptions::refine).
void RefineSeeds(const VerifierModel& model, std::span<const PreparedScan> scans, const SweepOptions& options,
                 const VerifyOptions& verify_options, SweepResult* sweep) {
  std::vector<const SweepPose*> seeds;
  for (const SweepPose& pose : sweep->poses) {
    const VerifyResult& r = pose.result;
    if (r.has_comparable_pairs && r.comparable_pairs >= options.min_comparable_pairs &&
        r.consistency > options.refine_min_consistency && r.confidence > options.refine_min_confidence) {
      seeds.push_back(&pose);
    }
  }
  std::stable_sort(seeds.begin(), seeds.end(), [](const SweepPose* a, const SweepPose* b) {
    return Score(a->result) > Score(b->result);
  });
  // Thin the seeds: one per half NMS radius.
  std::vector<const SweepPose*> kept;
  for (const SweepPose* seed : seeds) {
    bool near = false;
    for (const SweepPose* other : kept) {
      near = near || std::hypot(other->x_m - seed->x_m, other->y_m - seed->y_m) < 0.5 * sweep->nms_radius_m;
    }
    if (!near) kept.push_back(seed);
    if (static_cast<int>(kept.size()) >= options.refine_max_seeds) break;
  }
  double yaw_step = 360.0;
  if (options.yaws_deg.size() > 1) {
    std::vector<double> yaws = options.yaws_deg;
    std::sort(yaws.begin(), yaws.end());
    for (size_t i = 1; i < yaws.size(); ++i) {
      if (yaws[i] > yaws[i - 1]) yaw_step = std::min(yaw_step, yaws[i] - yaws[i - 1]);
    }
  }
  sweep->refined.resize(kept.size());
  std::vector<int64_t> evaluations(kept.size(), 0);
  ParallelFor(static_cast<int64_t>(kept.size()), [&](int64_t k) {
    SweepPose best = *kept[k];
    double step = 0.5 * options.step_m, yaw = 0.5 * yaw_step;
    for (int level = 0; level < 30; ++level) {
      bool improved = true;
      while (improved) {
        improved = false;
        const double moves[6][3] = {{step, 0, 0},  {-step, 0, 0}, {0, step, 0},
                                    {0, -step, 0}, {0, 0, yaw},   {0, 0, -yaw}};
        SweepPose best_move = best;
        for (const auto& move : moves) {
          if (move[0] == 0 && move[1] == 0 && move[2] == 0) continue;
          SweepPose candidate;
          candidate.x_m = best.x_m + move[0];
          candidate.y_m = best.y_m + move[1];
          candidate.yaw_deg = best.yaw_deg + move[2];
          candidate.result = VerifyPose(
              model, scans, PoseFromXyzYaw(candidate.x_m, candidate.y_m, options.z_m, candidate.yaw_deg),
              verify_options);
          ++evaluations[k];
          if (Score(candidate.result) > Score(best_move.result) + 1e-9) best_move = std::move(candidate);
        }
        if (Score(best_move.result) > Score(best.result) + 1e-9) {
          best = std::move(best_move);
          improved = true;
        }
      }
      if (step <= options.refine_min_step_m && yaw <= options.refine_min_yaw_deg) break;
      step = std::max(0.5 * step, options.refine_min_step_m);
      yaw = std::max(0.5 * yaw, options.refine_min_yaw_deg);
    }
    sweep->refined[k] = std::move(best);
  });
  for (int64_t e : evaluations) sweep->refine_evaluations += e;
}

// The confidence threshold a grid pose must pass to matter: as a detection, or as a refinement seed.
double PassThreshold(const SweepOptions& options) {
  return options.refine ? std::min(options.min_confidence, options.refine_min_confidence)
                        : options.min_confidence;
}

// The coarse-to-fine search (sweep.h, sweep_bound.h): per yaw, blocks of coarse_block x coarse_block grid
// positions; a block whose confidence bound cannot pass is skipped (its poses keep evaluated = false and the
// bound), others split into quarters down to single positions, which are verified. Appends the indices of
// the poses to verify (in index order) and returns the number of bounds computed.
int64_t SelectByConfidenceBound(const VerifierModel& model, std::span<const PreparedScan> scans,
                                const SweepOptions& options, double sigma_m, SweepResult* sweep,
                                std::vector<size_t>* to_verify, Progress* progress) {
  const int nx = static_cast<int>(sweep->xs_m.size()), ny = static_cast<int>(sweep->ys_m.size());
  const int nyaw = static_cast<int>(sweep->yaws_deg.size());
  const int block = std::max(1, options.coarse_block);
  struct Block {
    int x0, x1, y0, y1;  // grid positions [x0, x1) x [y0, y1)
    double RadiusM(const SweepResult& s) const {
      return 0.5 * std::hypot(s.xs_m[x1 - 1] - s.xs_m[x0], s.ys_m[y1 - 1] - s.ys_m[y0]);
    }
  };
  std::vector<std::pair<int, Block>> roots;  // (yaw index, block)
  for (int iyaw = 0; iyaw < nyaw; ++iyaw) {
    for (int y0 = 0; y0 < ny; y0 += block) {
      for (int x0 = 0; x0 < nx; x0 += block) {
        roots.push_back({iyaw, Block{x0, std::min(nx, x0 + block), y0, std::min(ny, y0 + block)}});
      }
    }
  }
  double max_radius = 0.0;
  for (const auto& root : roots) max_radius = std::max(max_radius, root.second.RadiusM(*sweep));
  const verify_internal::SweepConfidenceBound bound(model, scans, options, sigma_m, max_radius);
  const double threshold = PassThreshold(options);
  // A bound is summed in another order than verify's confidence: a relative 1e-9 covers the rounding.
  const double stop_above = threshold - 1e-9;

  std::vector<uint8_t> verify_pose(sweep->poses.size(), 0);
  std::vector<int64_t> bounds_per_root(roots.size(), 0);
  ParallelFor(static_cast<int64_t>(roots.size()), [&](int64_t k) {
    const int iyaw = roots[k].first;
    const double yaw = sweep->yaws_deg[iyaw];
    std::vector<Block> stack = {roots[k].second};
    while (!stack.empty()) {
      const Block b = stack.back();
      stack.pop_back();
      const double cx = 0.5 * (sweep->xs_m[b.x0] + sweep->xs_m[b.x1 - 1]);
      const double cy = 0.5 * (sweep->ys_m[b.y0] + sweep->ys_m[b.y1 - 1]);
      const double upper = bound.UpperBound(cx, cy, yaw, b.RadiusM(*sweep), stop_above);
      ++bounds_per_root[k];
      const bool single = b.x1 - b.x0 == 1 && b.y1 - b.y0 == 1;
      if (upper <= stop_above || single) {
        const bool skip = upper <= stop_above;
        for (int iy = b.y0; iy < b.y1; ++iy) {
          for (int ix = b.x0; ix < b.x1; ++ix) {
            const size_t p = (static_cast<size_t>(iy) * nx + ix) * nyaw + iyaw;
            verify_pose[p] = skip ? 0 : 1;
            SweepPose& pose = sweep->poses[p];  // each pose belongs to one block: no race
            pose.evaluated = !skip;
            pose.confidence_bound = skip ? upper : 1.0;
          }
        }
        Advance(progress, static_cast<int64_t>(b.x1 - b.x0) * (b.y1 - b.y0));
        continue;
      }
      const int xm = b.x1 - b.x0 > 1 ? (b.x0 + b.x1) / 2 : b.x1;
      const int ym = b.y1 - b.y0 > 1 ? (b.y0 + b.y1) / 2 : b.y1;
      for (const Block child : {Block{b.x0, xm, b.y0, ym}, Block{xm, b.x1, b.y0, ym},
                                Block{b.x0, xm, ym, b.y1}, Block{xm, b.x1, ym, b.y1}}) {
        if (child.x1 > child.x0 && child.y1 > child.y0) stack.push_back(child);
      }
    }
  });
  for (size_t p = 0; p < verify_pose.size(); ++p) {
    if (verify_pose[p] != 0) to_verify->push_back(p);
  }
  int64_t total = 0;
  for (int64_t n : bounds_per_root) total += n;
  return total;
}

// The scanners' positions and the scene points a model on the ground could touch, for the heat maps.
void CollectPictureContext(const VerifierModel& model, std::span<const PreparedScan> scans,
                           const SweepOptions& options, SweepResult* sweep) {
  const double half_x = 0.5 * (sweep->xs_m.size() > 1 ? sweep->xs_m[1] - sweep->xs_m[0] : options.step_m);
  const double x_lo = sweep->xs_m.front() - half_x, x_hi = sweep->xs_m.back() + half_x;
  const double y_lo = sweep->ys_m.front() - half_x, y_hi = sweep->ys_m.back() + half_x;
  // Above the ground (20 cm: noise and gravel) and below the model's top.
  const double z_lo = options.z_m + std::max(0.2, double{model.bounds_in_model.min().z()});
  const double z_hi = options.z_m + std::max(0.4, double{model.bounds_in_model.max().z()});
  constexpr double kThinM = 0.02;
  const int64_t columns = static_cast<int64_t>(std::ceil((x_hi - x_lo) / kThinM)) + 1;
  std::vector<int64_t> seen;
  for (const PreparedScan& prepared : scans) {
    const Eigen::Vector3d origin = prepared.world_from_scanner.topRightCorner<3, 1>();
    sweep->scanner_xy_m.emplace_back(origin.x(), origin.y());
    const Scan& scan = prepared.scan;
    for (int r = 0; r < scan.rows; ++r) {
      for (int c = 0; c < scan.cols; ++c) {
        if (scan.valid.at<uint8_t>(r, c) == 0 || !(scan.range.at<float>(r, c) > 0)) continue;
        const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
        const Eigen::Vector3d q =
            (prepared.world_from_scanner * Eigen::Vector4d(p[0], p[1], p[2], 1.0)).head<3>();
        if (!(q.z() > z_lo && q.z() < z_hi && q.x() >= x_lo && q.x() < x_hi && q.y() >= y_lo &&
              q.y() < y_hi)) {
          continue;
        }
        seen.push_back(static_cast<int64_t>((q.y() - y_lo) / kThinM) * columns +
                       static_cast<int64_t>((q.x() - x_lo) / kThinM));
      }
    }
  }
  std::sort(seen.begin(), seen.end());
  seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
  sweep->scene_xy_m.reserve(seen.size());
  for (int64_t key : seen) {
    sweep->scene_xy_m.emplace_back(
        static_cast<float>(x_lo + (static_cast<double>(key % columns) + 0.5) * kThinM),
        static_cast<float>(y_lo + (static_cast<double>(key / columns) + 0.5) * kThinM));
  }
}

}  // namespace

void SweepOptions::Check() const {
  Validate(*this);
  const double positions =
      (std::floor((x_max_m - x_min_m) / step_m) + 1) * (std::floor((y_max_m - y_min_m) / step_m) + 1);
  CheckMemoryBudget(static_cast<int64_t>(positions * static_cast<double>(yaws_deg.size()) * 200),
                    fmt::format("a sweep of {} poses", positions * static_cast<double>(yaws_deg.size())));
}

std::vector<Detection> SelectDetections(std::span<const SweepPose> poses, const SweepOptions& options,
                                        double nms_radius_m, double z_m) {
  std::vector<const SweepPose*> candidates;
  for (const SweepPose& pose : poses) {
    const VerifyResult& r = pose.result;
    if (r.has_comparable_pairs && r.comparable_pairs >= options.min_comparable_pairs &&
        r.consistency > options.min_consistency && r.confidence > options.min_confidence) {
      candidates.push_back(&pose);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const SweepPose* a, const SweepPose* b) {
    if (a->result.confidence != b->result.confidence) return a->result.confidence > b->result.confidence;
    return a->result.consistency > b->result.consistency;
  });
  std::vector<Detection> detections;
  for (const SweepPose* pose : candidates) {
    bool suppressed = false;
    for (const Detection& kept : detections) {
      if (std::hypot(kept.x_m - pose->x_m, kept.y_m - pose->y_m) < nms_radius_m) {
        suppressed = true;
        break;
      }
    }
    if (suppressed) continue;
    Detection detection;
    detection.x_m = pose->x_m;
    detection.y_m = pose->y_m;
    detection.z_m = z_m;
    detection.yaw_deg = pose->yaw_deg;
    detection.world_from_model = PoseFromXyzYaw(pose->x_m, pose->y_m, z_m, pose->yaw_deg);
    detection.consistency = pose->result.consistency;
    detection.confidence = pose->result.confidence;
    detection.icp_cost_m = pose->result.icp_cost_m;
    detection.inlier_fraction = pose->result.inlier_fraction;
    detection.comparable_pairs = pose->result.comparable_pairs;
    detections.push_back(detection);
  }
  return detections;
}

SweepResult Sweep(const VerifierModel& model, std::span<const PreparedScan> scans,
                  const SweepOptions& sweep_options, const VerifyOptions& verify_options,
                  Progress* progress) {
  sweep_options.Check();
  verify_options.Check();
  SweepResult sweep;
  sweep.xs_m = Range(sweep_options.x_min_m, sweep_options.x_max_m, sweep_options.step_m);
  sweep.ys_m = Range(sweep_options.y_min_m, sweep_options.y_max_m, sweep_options.step_m);
  sweep.yaws_deg = sweep_options.yaws_deg;
  const size_t nx = sweep.xs_m.size(), ny = sweep.ys_m.size(), nyaw = sweep.yaws_deg.size();
  std::vector<Eigen::Matrix4d> poses;
  poses.reserve(nx * ny * nyaw);
  sweep.poses.resize(nx * ny * nyaw);
  for (size_t iy = 0; iy < ny; ++iy) {
    for (size_t ix = 0; ix < nx; ++ix) {
      for (size_t iyaw = 0; iyaw < nyaw; ++iyaw) {
        SweepPose& pose = sweep.poses[(iy * nx + ix) * nyaw + iyaw];
        pose.x_m = sweep.xs_m[ix];
        pose.y_m = sweep.ys_m[iy];
        pose.yaw_deg = sweep.yaws_deg[iyaw];
        poses.push_back(PoseFromXyzYaw(pose.x_m, pose.y_m, sweep_options.z_m, pose.yaw_deg));
      }
    }
  }
  VerifyOptions options = verify_options;
  options.keep_details = false;
  std::vector<size_t> to_verify;  // indices into sweep.poses
  if (sweep_options.search == SweepSearch::kCoarseToFine) {
    if (progress != nullptr) progress->Restart("sweep: bounds", static_cast<int64_t>(sweep.poses.size()));
    sweep.bound_evaluations = SelectByConfidenceBound(model, scans, sweep_options, verify_options.sigma_m,
                                                      &sweep, &to_verify, progress);
    if (progress != nullptr) progress->Restart("sweep", static_cast<int64_t>(to_verify.size()));
  } else {
    to_verify.resize(sweep.poses.size());
    for (size_t p = 0; p < to_verify.size(); ++p) to_verify[p] = p;
  }
  std::vector<Eigen::Matrix4d> chosen;
  chosen.reserve(to_verify.size());
  for (size_t p : to_verify) chosen.push_back(poses[p]);
  poses.clear();
  poses.shrink_to_fit();
  std::vector<VerifyResult> results = VerifyPoses(model, scans, chosen, options, progress);
  for (size_t k = 0; k < results.size(); ++k) {
    SweepPose& pose = sweep.poses[to_verify[k]];
    pose.result = std::move(results[k]);
    pose.evaluated = true;
    pose.confidence_bound = 1.0;
  }
  sweep.evaluated_poses = static_cast<int64_t>(to_verify.size());

  const float nan = std::numeric_limits<float>::quiet_NaN();
  sweep.consistency_map = cv::Mat(static_cast<int>(ny), static_cast<int>(nx), CV_32F, cv::Scalar(nan));
  sweep.confidence_map = cv::Mat(static_cast<int>(ny), static_cast<int>(nx), CV_32F, cv::Scalar(nan));
  sweep.evaluated_map = cv::Mat::zeros(static_cast<int>(ny), static_cast<int>(nx), CV_8U);
  for (size_t iy = 0; iy < ny; ++iy) {
    const int row = static_cast<int>(ny - 1 - iy);  // north up
    for (size_t ix = 0; ix < nx; ++ix) {
      float& consistency = sweep.consistency_map.at<float>(row, static_cast<int>(ix));
      float& confidence = sweep.confidence_map.at<float>(row, static_cast<int>(ix));
      uint8_t& evaluated = sweep.evaluated_map.at<uint8_t>(row, static_cast<int>(ix));
      for (size_t iyaw = 0; iyaw < nyaw; ++iyaw) {
        const SweepPose& pose = sweep.poses[(iy * nx + ix) * nyaw + iyaw];
        if (!pose.evaluated) continue;
        evaluated = static_cast<uint8_t>(std::min<size_t>(255, evaluated + 1));
        const VerifyResult& r = pose.result;
        if (r.has_comparable_pairs && (std::isnan(consistency) || r.consistency > consistency)) {
          consistency = static_cast<float>(r.consistency);
        }
        if (std::isnan(confidence) || r.confidence > confidence)
          confidence = static_cast<float>(r.confidence);
      }
    }
  }
  CollectPictureContext(model, scans, sweep_options, &sweep);
  sweep.nms_radius_m = sweep_options.nms_radius_m;
  if (sweep.nms_radius_m <= 0) {
    const Eigen::Vector3f size = model.bounds_in_model.sizes();
    sweep.nms_radius_m = std::min(size.x(), size.y());
  }
  if (sweep_options.refine) RefineSeeds(model, scans, sweep_options, options, &sweep);
  std::vector<SweepPose> all = sweep.refined;
  all.insert(all.end(), sweep.poses.begin(), sweep.poses.end());
  sweep.detections = SelectDetections(all, sweep_options, sweep.nms_radius_m, sweep_options.z_m);
  return sweep;
}

SweepSummary SummarizeSweep(const SweepResult& sweep, const SweepOptions& options) {
  SweepSummary summary;
  summary.detections = sweep.detections;
  for (Detection& detection : summary.detections)
    detection.world_from_model = RoundedPose(detection.world_from_model);
  summary.thresholds = {.min_comparable_pairs = options.min_comparable_pairs,
                        .min_confidence = options.min_confidence,
                        .min_consistency = options.min_consistency,
                        .nms_radius_m = sweep.nms_radius_m};
  summary.grid = {.bound_evaluations = sweep.bound_evaluations,
                  .evaluated_poses = sweep.evaluated_poses,
                  .poses = sweep.poses.size(),
                  .refine_evaluations = sweep.refine_evaluations,
                  .refined_seeds = sweep.refined.size(),
                  .search = options.search,
                  .x_count = sweep.xs_m.size(),
                  .y_count = sweep.ys_m.size(),
                  .yaws_deg = sweep.yaws_deg};
  return summary;
}

std::string SweepCsv(const SweepResult& sweep) {
  std::string csv = "x_m,y_m,yaw_deg,consistency,confidence,comparable_pairs,icp_cost_m,inlier_fraction\n";
  for (const SweepPose& pose : sweep.poses) {
    if (!pose.evaluated) continue;
    const VerifyResult& r = pose.result;
    csv += fmt::format("{:.4f},{:.4f},{:.3f},{},{:.6f},{},{},{:.6f}\n", pose.x_m, pose.y_m, pose.yaw_deg,
                       Field(r.consistency), r.confidence, r.comparable_pairs, Field(r.icp_cost_m),
                       r.inlier_fraction);
  }
  return csv;
}

}  // namespace lidarshop
