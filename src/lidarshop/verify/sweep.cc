#include "lidarshop/verify/sweep.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/progress.h"

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
  std::vector<VerifyResult> results = VerifyPoses(model, scans, poses, options, progress);
  for (size_t p = 0; p < results.size(); ++p) sweep.poses[p].result = std::move(results[p]);

  sweep.consistency_map = cv::Mat(static_cast<int>(ny), static_cast<int>(nx), CV_32F,
                                  cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  sweep.confidence_map = cv::Mat(static_cast<int>(ny), static_cast<int>(nx), CV_32F, cv::Scalar(0.0f));
  for (size_t iy = 0; iy < ny; ++iy) {
    const int row = static_cast<int>(ny - 1 - iy);  // north up
    for (size_t ix = 0; ix < nx; ++ix) {
      float& consistency = sweep.consistency_map.at<float>(row, static_cast<int>(ix));
      float& confidence = sweep.confidence_map.at<float>(row, static_cast<int>(ix));
      for (size_t iyaw = 0; iyaw < nyaw; ++iyaw) {
        const VerifyResult& r = sweep.poses[(iy * nx + ix) * nyaw + iyaw].result;
        if (r.has_comparable_pairs && (std::isnan(consistency) || r.consistency > consistency)) {
          consistency = static_cast<float>(r.consistency);
        }
        confidence = std::max(confidence, static_cast<float>(r.confidence));
      }
    }
  }
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

cv::Mat RenderHeatMap(const cv::Mat& values, const SweepResult& sweep, const std::string& title,
                      double threshold, int cell_px) {
  LIDARSHOP_CHECK(values.type() == CV_32F);
  const int rows = values.rows, cols = values.cols;
  if (cell_px <= 0) cell_px = std::clamp(600 / std::max(1, std::max(rows, cols)), 1, 40);
  const int map_w = cols * cell_px, map_h = rows * cell_px;
  const int margin = 10, top = 36, bottom = 40, bar_w = 24, bar_gap = 16, label_w = 50;
  const int width = margin + map_w + bar_gap + bar_w + label_w + margin;
  const int height = top + std::max(map_h, 120) + bottom;
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));

  // Colours: 8-bit levels through viridis (OpenCV returns BGR; flipped to RGB at the end).
  cv::Mat levels(rows, cols, CV_8U), nan_mask(rows, cols, CV_8U);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const float v = values.at<float>(r, c);
      nan_mask.at<uint8_t>(r, c) = std::isnan(v) ? 255 : 0;
      levels.at<uint8_t>(r, c) =
          std::isnan(v) ? 0 : static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255));
    }
  }
  cv::Mat colored;
  cv::applyColorMap(levels, colored, cv::COLORMAP_VIRIDIS);
  colored.setTo(cv::Scalar(150, 150, 150), nan_mask);
  cv::Mat scaled;
  cv::resize(colored, scaled, cv::Size(map_w, map_h), 0, 0, cv::INTER_NEAREST);
  scaled.copyTo(canvas(cv::Rect(margin, top, map_w, map_h)));

  // Detections as rings.
  if (!sweep.xs_m.empty() && !sweep.ys_m.empty()) {
    const double step_x = sweep.xs_m.size() > 1 ? sweep.xs_m[1] - sweep.xs_m[0] : 1.0;
    const double step_y = sweep.ys_m.size() > 1 ? sweep.ys_m[1] - sweep.ys_m[0] : 1.0;
    for (const Detection& d : sweep.detections) {
      const double fx = (d.x_m - sweep.xs_m.front()) / step_x + 0.5;
      const double fy = (sweep.ys_m.back() - d.y_m) / step_y + 0.5;
      const cv::Point centre(margin + static_cast<int>(fx * cell_px), top + static_cast<int>(fy * cell_px));
      cv::circle(canvas, centre, std::max(6, 2 * cell_px), cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
      cv::circle(canvas, centre, std::max(6, 2 * cell_px) + 2, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    }
  }

  // Colour scale.
  const int bar_x = margin + map_w + bar_gap;
  const int bar_h = std::max(map_h, 120);
  for (int y = 0; y < bar_h; ++y) {
    cv::Mat level(1, 1, CV_8U,
                  cv::Scalar(static_cast<int>(std::lround(255.0 * (bar_h - 1 - y) / (bar_h - 1)))));
    cv::Mat color;
    cv::applyColorMap(level, color, cv::COLORMAP_VIRIDIS);
    const cv::Vec3b bgr = color.at<cv::Vec3b>(0, 0);
    cv::line(canvas, cv::Point(bar_x, top + y), cv::Point(bar_x + bar_w - 1, top + y),
             cv::Scalar(bgr[0], bgr[1], bgr[2]));
  }
  cv::rectangle(canvas, cv::Rect(bar_x, top, bar_w, bar_h), cv::Scalar(0, 0, 0), 1);
  for (int tick = 0; tick <= 4; ++tick) {
    const int y = top + static_cast<int>(std::lround((bar_h - 1) * (1.0 - tick / 4.0)));
    cv::line(canvas, cv::Point(bar_x + bar_w, y), cv::Point(bar_x + bar_w + 4, y), cv::Scalar(0, 0, 0));
    cv::putText(canvas, fmt::format("{:.2f}", tick / 4.0), cv::Point(bar_x + bar_w + 6, y + 4),
                cv::FONT_HERSHEY_SIMPLEX, 0.38, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  if (threshold >= 0 && threshold <= 1) {
    const int y = top + static_cast<int>(std::lround((bar_h - 1) * (1.0 - threshold)));
    cv::line(canvas, cv::Point(bar_x - 4, y), cv::Point(bar_x + bar_w + 4, y), cv::Scalar(0, 0, 255), 2);
  }
  cv::putText(canvas, title, cv::Point(margin, 24), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  if (!sweep.xs_m.empty() && !sweep.ys_m.empty()) {
    cv::putText(canvas,
                fmt::format("x {:.1f}..{:.1f} m (right), y {:.1f}..{:.1f} m (up); grey = no comparable pair",
                            sweep.xs_m.front(), sweep.xs_m.back(), sweep.ys_m.front(), sweep.ys_m.back()),
                cv::Point(margin, top + bar_h + 24), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
  }
  cv::Mat rgb;
  cv::cvtColor(canvas, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

std::string SweepCsv(const SweepResult& sweep) {
  std::string csv = "x_m,y_m,yaw_deg,consistency,confidence,comparable_pairs,icp_cost_m,inlier_fraction\n";
  for (const SweepPose& pose : sweep.poses) {
    const VerifyResult& r = pose.result;
    csv += fmt::format("{:.4f},{:.4f},{:.3f},{},{:.6f},{},{},{:.6f}\n", pose.x_m, pose.y_m, pose.yaw_deg,
                       Field(r.consistency), r.confidence, r.comparable_pairs, Field(r.icp_cost_m),
                       r.inlier_fraction);
  }
  return csv;
}

}  // namespace lidarshop
