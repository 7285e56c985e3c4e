// Sweeps: consistency and confidence for a grid of candidate poses on a ground plane, heat maps, and
// detections that pass both thresholds, with non-maximum suppression.
//
// Candidate poses are world_from_model = PoseFromXyzYaw(x, y, z_m, yaw) for x in [x_min, x_max] and y in
// [y_min, y_max] in steps of step_m, and every yaw of yaws_deg. A detection is a pose with
//   consistency > min_consistency  and  confidence > min_confidence
//   and  comparable_pairs >= min_comparable_pairs,
// kept greedily by decreasing confidence unless a kept detection lies within nms_radius_m (in x, y).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/verify/verify.h"

namespace lidarshop {

struct SweepOptions {
  double x_min_m = -10.0, x_max_m = 10.0;  // metres, world x range of the model origin (inclusive)
  double y_min_m = 0.0, y_max_m = 20.0;    // metres, world y range
  double step_m = 0.25;                    // metres between candidate positions (x and y)
  double z_m = 0.0;                        // metres, world z of the model origin (the ground for a car model)
  std::vector<double> yaws_deg = {0, 30, 60, 90, 120, 150, 180, 210, 240, 270, 300, 330};  // degrees about +z
  double min_consistency = 0.75;      // detections need consistency > this
  double min_confidence = 0.3;        // ... and confidence > this
  int64_t min_comparable_pairs = 50;  // ... and at least this many comparable pairs (a few rays prove little)
  double nms_radius_m = 0.0;       // metres; 0 = the model's smaller horizontal extent (two objects of this
                                   // shape cannot stand closer)
  int64_t max_poses = 20'000'000;  // refuse larger sweeps (memory: ~200 bytes a pose)
  // Local refinement: both measures are sharp (0.25 m or 7.5° off the truth already costs a car ~0.25 of
  // consistency and most of its confidence), so a coarse grid rarely holds a pose that passes. Grid poses
  // with consistency > refine_min_consistency and confidence > refine_min_confidence (at most
  // refine_max_seeds of them, the best first, thinned by NMS) are refined by coordinate ascent of consistency
  // + confidence over x, y and yaw, steps halved from half the grid steps down to refine_min_step_m /
  // refine_min_yaw_deg. Detections come from the refined poses (and the grid).
  bool refine = true;
  double refine_min_consistency = 0.5;
  double refine_min_confidence = 0.05;
  int refine_max_seeds = 64;
  double refine_min_step_m = 0.02;  // metres
  double refine_min_yaw_deg = 0.5;  // degrees

  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<SweepOptions>();

struct Detection {
  double x_m = 0, y_m = 0, z_m = 0, yaw_deg = 0;
  Eigen::Matrix4d world_from_model = Eigen::Matrix4d::Identity();
  double consistency = 0, confidence = 0, icp_cost_m = 0, inlier_fraction = 0;
  int64_t comparable_pairs = 0;
};

struct SweepPose {
  double x_m = 0, y_m = 0, yaw_deg = 0;
  VerifyResult result;  // without details
};

struct SweepResult {
  std::vector<double> xs_m, ys_m, yaws_deg;  // the grid: #X, #Y, #yaws
  std::vector<SweepPose> poses;              // #Y * #X * #yaws, index (iy * #X + ix) * #yaws + iyaw
  // Heat maps, CV_32F, #Y rows x #X cols, row 0 = the largest y (north up), column 0 = the smallest x: the
  // best value over yaws at each position (each map maximised on its own). NaN where no yaw had a comparable
  // pair (consistency) or never (confidence is always defined).
  cv::Mat consistency_map;
  cv::Mat confidence_map;
  std::vector<Detection> detections;  // by decreasing confidence
  std::vector<SweepPose> refined;     // the refined poses (empty without refinement)
  int64_t refine_evaluations = 0;     // poses verified during refinement
  double nms_radius_m = 0;            // the radius used
};

SweepResult Sweep(const VerifierModel& model, std::span<const PreparedScan> scans,
                  const SweepOptions& sweep_options, const VerifyOptions& verify_options,
                  Progress* progress = nullptr);

// The detections of already verified poses (dual threshold + NMS), by decreasing confidence.
std::vector<Detection> SelectDetections(std::span<const SweepPose> poses, const SweepOptions& options,
                                        double nms_radius_m, double z_m);

// A heat map as an RGB picture: each cell a square of `cell_px` pixels (0 = automatic, about 600 px across),
// viridis colours for [0, 1], grey where NaN, a colour scale with ticks at 0, 0.25, …, 1 and a mark at
// `threshold` (< 0 = none), the title and the x/y ranges written on it, and a white ring at each detection.
cv::Mat RenderHeatMap(const cv::Mat& values, const SweepResult& sweep, const std::string& title,
                      double threshold, int cell_px = 0);

// One line per pose: x_m,y_m,yaw_deg,consistency,confidence,comparable_pairs,icp_cost_m,inlier_fraction
// (empty fields where NaN).
std::string SweepCsv(const SweepResult& sweep);

}  // namespace lidarshop
