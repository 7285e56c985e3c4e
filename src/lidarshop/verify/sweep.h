// Sweeps: consistency and confidence for a grid of candidate poses on a ground plane, heat maps, and
// detections that pass both thresholds, with non-maximum suppression.
//
// Candidate poses are world_from_model = PoseFromXyzYaw(x, y, z_m, yaw) for x in [x_min, x_max] and y in
// [y_min, y_max] in steps of step_m, and every yaw of yaws_deg. A detection is a pose with
//   consistency > min_consistency  and  confidence > min_confidence
//   and  comparable_pairs >= min_comparable_pairs,
// kept greedily by decreasing confidence unless a kept detection lies within nms_radius_m (in x, y).
//
// Search (SweepOptions::search): `kFull` verifies every grid pose; `kCoarseToFine` (default) first bounds
// the confidence of whole blocks of grid poses from above (sweep_bound.h: the model's points may move by at
// most the block's radius, so a model point can only be observed where scene points lie within 3σ of the
// block's swept positions) and verifies only the poses of blocks whose bound can still pass, splitting
// blocks into quarters down to single poses. A skipped pose provably has confidence ≤ its block's bound ≤
// the confidence threshold of detections and of refinement seeds, so both searches give the same
// detections, the same refinement seeds and the same refined poses (sweep_search_test).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/verify/verify.h"

namespace lidarshop {

enum class SweepSearch {
  kFull,          // verify every grid pose
  kCoarseToFine,  // verify only the grid poses whose confidence bound can still pass (same detections)
};
template <>
const EnumInfo& EnumInfoOf<SweepSearch>();  // "full", "coarse-to-fine"

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
  SweepSearch search = SweepSearch::kCoarseToFine;
  int coarse_block = 16;  // grid positions along x and y of the coarsest blocks of the coarse-to-fine search

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
  // False: skipped by the coarse-to-fine search, which proved confidence ≤ confidence_bound (≤ the
  // thresholds); `result` is then empty (no comparable pair, confidence 0).
  bool evaluated = true;
  double confidence_bound = 1.0;  // an upper bound of the confidence (1 when evaluated)
};

struct SweepResult {
  std::vector<double> xs_m, ys_m, yaws_deg;  // the grid: #X, #Y, #yaws
  std::vector<SweepPose> poses;              // #Y * #X * #yaws, index (iy * #X + ix) * #yaws + iyaw
  // Heat maps, CV_32F, #Y rows x #X cols, row 0 = the largest y (north up), column 0 = the smallest x: the
  // best value over the evaluated yaws at each position (each map maximised on its own). NaN where no yaw
  // had a comparable pair (consistency) or where no yaw was evaluated (both; coarse-to-fine only).
  cv::Mat consistency_map;
  cv::Mat confidence_map;
  cv::Mat evaluated_map;          // CV_8U, same layout: how many yaws were verified at each position
  int64_t evaluated_poses = 0;    // grid poses verified (all of them with SweepSearch::kFull)
  int64_t bound_evaluations = 0;  // blocks whose confidence was bounded (coarse-to-fine)
  // For the heat maps' pictures: the scanners' positions (world x, y, metres) and the scene points that a
  // model on the ground could touch (world z within the model's height above z_m, the ground left out),
  // projected onto the ground plane (x, y, metres), at most one per 2 cm square.
  std::vector<Eigen::Vector2d> scanner_xy_m;
  std::vector<Eigen::Vector2f> scene_xy_m;
  std::vector<Detection> detections;  // by decreasing confidence
  std::vector<SweepPose> refined;     // the refined poses (empty without refinement)
  int64_t refine_evaluations = 0;     // poses verified during refinement
  double nms_radius_m = 0;            // the radius used
};

// Described with its keys in alphabetical order, as detections.json has always been written.
template <>
const StructInfo& InfoOf<Detection>();

// The thresholds a sweep's detections passed.
struct SweepThresholds {
  int64_t min_comparable_pairs = 0;  // SweepOptions::min_comparable_pairs
  double min_confidence = 0;         // SweepOptions::min_confidence
  double min_consistency = 0;        // SweepOptions::min_consistency
  double nms_radius_m = 0;           // metres, the radius used (SweepResult::nms_radius_m)
};
template <>
const StructInfo& InfoOf<SweepThresholds>();

// The grid a sweep covered and how much of it was verified.
struct SweepGridSummary {
  int64_t bound_evaluations = 0;   // blocks whose confidence was bounded (coarse-to-fine)
  int64_t evaluated_poses = 0;     // grid poses verified
  uint64_t poses = 0;              // grid poses, #X * #Y * #yaws
  int64_t refine_evaluations = 0;  // poses verified during refinement
  uint64_t refined_seeds = 0;      // grid poses refined
  SweepSearch search = SweepSearch::kCoarseToFine;
  uint64_t x_count = 0, y_count = 0;  // grid positions along x and y
  std::vector<double> yaws_deg;       // degrees, the yaws tried
};
template <>
const StructInfo& InfoOf<SweepGridSummary>();

// A sweep's outcome without its pictures and poses (detections.json).
struct SweepSummary {
  // By decreasing confidence; each world_from_model rounded as reported (geometry/transform.h RoundedPose).
  std::vector<Detection> detections;
  SweepGridSummary grid;
  SweepThresholds thresholds;
};
template <>
const StructInfo& InfoOf<SweepSummary>();

// What `lidarshop sweep --json` reports: SweepSummary's keys, then the options of both sides.
struct SweepReport {
  SweepSummary summary;  // written flat: detections, grid, thresholds
  VerifyOptions verify_options;
  ModelOptions model_options;
};
template <>
const StructInfo& InfoOf<SweepReport>();

SweepSummary SummarizeSweep(const SweepResult& sweep, const SweepOptions& options);

SweepResult Sweep(const VerifierModel& model, std::span<const PreparedScan> scans,
                  const SweepOptions& sweep_options, const VerifyOptions& verify_options,
                  Progress* progress = nullptr);

// The detections of already verified poses (dual threshold + NMS), by decreasing confidence.
std::vector<Detection> SelectDetections(std::span<const SweepPose> poses, const SweepOptions& options,
                                        double nms_radius_m, double z_m);

// Where RenderHeatMap puts things: the map's rectangle in the picture and the pixel of a world position.
struct HeatMapLayout {
  cv::Rect map;                           // the heat map's cells, pixels
  int cell_px = 0;                        // pixels per grid cell
  double x0_m = 0, y1_m = 0, step_m = 1;  // x of column 0's centre, y of row 0's centre, metres per cell
  cv::Point2d PixelOf(double x_m, double y_m) const;  // picture pixel (x right, y down) of world (x, y)
};
HeatMapLayout HeatMapLayoutOf(const cv::Mat& values, const SweepResult& sweep, int cell_px = 0);

// RGB colour of the scanner marks in heat-map pictures (magenta: in no colour map, ring or scale).
inline const cv::Vec3b kHeatMapScannerRgb(255, 0, 255);

// A heat map as an RGB picture: each cell a square of `cell_px` pixels (0 = automatic, about 600 px across),
// viridis colours for [0, 1], grey where NaN, pale where no pose was verified (coarse-to-fine), the scene
// points (SweepResult::scene_xy_m) darkening the cells they fall in, x and y axes with ticks and labels in
// metres, a magenta mark at each scanner inside the map, a colour scale with ticks at 0, 0.25, …, 1 and a
// mark at `threshold` (< 0 = none), the title, and a white ring at each detection.
cv::Mat RenderHeatMap(const cv::Mat& values, const SweepResult& sweep, const std::string& title,
                      double threshold, int cell_px = 0);

// One line per verified pose (every grid pose with SweepSearch::kFull):
// x_m,y_m,yaw_deg,consistency,confidence,comparable_pairs,icp_cost_m,inlier_fraction (empty fields where NaN).
std::string SweepCsv(const SweepResult& sweep);

}  // namespace lidarshop
