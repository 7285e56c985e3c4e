// auto_resection_eval: the automatic resection's table of bench/results/recolor.md. For each seed a textured
// random street scene (recolor/auto_resection_test_util.h) is scanned and photographed from a known camera
// 0.2–2 m from the scanner; AutoResection (recolor/auto_resection.h) recovers the camera from the scan and the
// photo alone. A case succeeds when the camera centre is within 2 cm and the orientation within 0.1° of the
// truth. Seeds 1-50 are the evaluation; development used seeds from 1001 on.
//
//   auto_resection_eval --first-seed 1 --seeds 50 [--unknown-focal] [--threads 2] [--out table.md]
//   auto_resection_eval --pumpa   # pumpA's photo: RMS of the automatic camera on the 16 hand-picked pairs
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/recolor/auto_resection.h"
#include "lidarshop/recolor/auto_resection_test_util.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/util/error.h"

using namespace lidarshop;

namespace {

double AngleDeg(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const Eigen::Matrix3d r = a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>();
  return std::acos(std::clamp((r.trace() - 1) / 2, -1.0, 1.0)) * 180 / M_PI;
}

// Nearest-rank percentile of sorted values.
double Percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return NAN;
  const size_t rank = static_cast<size_t>(std::max(1.0, std::ceil(p / 100 * sorted.size()))) - 1;
  return sorted[std::min(rank, sorted.size() - 1)];
}

// `rough_offset_m` > 0: start from the hand-picked pairs' camera moved by this much (and turned by
// `rough_turn_deg`) instead of searching from the scanner centre.
int RunPumpA(const AutoResectionOptions& options, bool unknown_focal, double rough_offset_m,
             double rough_turn_deg, bool verbose) {
  const std::string scan_path = LIDARSHOP_SHARED_DATA_DIR "/e57/pumpA.e57";
  const E57File file = ReadE57(scan_path);
  const ScanFile scans = ReadScanFile(scan_path);
  cv::Mat photo;
  for (const E57Image& image : file.images)
    if (!image.image.empty() && image.image.cols == 3072) photo = image.image;
  if (photo.empty()) throw InputError(scan_path + ": no 3072 x 2304 image");
  const Correspondences pairs = ReadCorrespondences(
      LIDARSHOP_SOURCE_DIR "/data/recolor/pumpA_correspondences.json", &scans.scans.at(0));
  std::optional<PinholeCamera> intrinsics;
  if (!unknown_focal)
    intrinsics = ReadCameraJson(LIDARSHOP_SOURCE_DIR "/data/recolor/pumpA_intrinsics_exif.json");
  const PinholeCamera exif = ReadCameraJson(LIDARSHOP_SOURCE_DIR "/data/recolor/pumpA_intrinsics_exif.json");
  ResectionOptions hand_options;
  hand_options.width_px = 3072, hand_options.height_px = 2304, hand_options.ransac_threshold_px = 40;
  const PinholeCamera hand = ResectWithIntrinsics(pairs.pixel_point, exif, hand_options).camera;
  std::optional<Eigen::Matrix4d> rough;
  if (rough_offset_m > 0) {
    Eigen::Matrix4d pose = hand.world_from_camera;
    pose.topRightCorner<3, 1>() += rough_offset_m * Eigen::Vector3d(1, 1, 1).normalized();
    pose.topLeftCorner<3, 3>() =
        pose.topLeftCorner<3, 3>() *
        Eigen::AngleAxisd(rough_turn_deg * M_PI / 180, Eigen::Vector3d(1, 1, 0).normalized())
            .toRotationMatrix();
    rough = pose;
    fmt::print("pumpA: rough pose = the hand-picked pairs' camera moved {:.2f} m and turned {:.1f}°\n",
               rough_offset_m, rough_turn_deg);
  }
  const auto start = std::chrono::steady_clock::now();
  try {
    const AutoResectionResult result =
        AutoResection(scans.scans.at(0), photo, options, intrinsics, rough, "pumpA");
    fmt::print("  camera vs the hand-picked pairs' camera: {:.3f} m, {:.3f}°\n",
               (result.camera.center_in_world() - hand.center_in_world()).norm(),
               AngleDeg(result.camera.world_from_camera, hand.world_from_camera));
    double sum = 0;
    for (const PixelPointPair& pair : pairs.pixel_point) {
      const double e = ReprojectionError(result.camera, pair);
      sum += e * e;
    }
    if (result.method == "silhouettes")
      fmt::print("  silhouettes: {:.0f} % of the model edges on a photo edge, mutual information {:.3f}\n",
                 100 * result.silhouette_edge_share, result.silhouette_mutual_information);
    if (verbose) fmt::print("  trace: {}\n", result.trace);
    fmt::print("pumpA: {}\n  RMS on the {} hand-picked pairs: {:.2f} px ({:.1f} s)\n", result.Summary(),
               pairs.pixel_point.size(), std::sqrt(sum / pairs.pixel_point.size()),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  } catch (const InputError& e) {
    fmt::print("pumpA: refused ({:.1f} s): {}\n",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), e.what());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Automatic resection on textured random street scenes (bench/results/recolor.md)"};
  int first_seed = 1, seeds = 50, threads = 2, rows = 600, columns = 900;
  bool unknown_focal = false, pumpa = false, verbose = false;
  std::string out_path, dump_dir;
  double rough_offset_m = 0, rough_turn_deg = 0;
  app.add_option("--rough-offset", rough_offset_m, "--pumpa: start this far (m) from the hand pairs' camera");
  app.add_option("--rough-turn", rough_turn_deg, "--pumpa: and turned this much (degrees)");
  app.add_option("--first-seed", first_seed, "first seed (evaluation: 1; development: 1001)");
  app.add_option("--seeds", seeds, "number of cases");
  app.add_option("--threads", threads, "OpenCV threads");
  app.add_option("--rows", rows, "scan rows");
  app.add_option("--columns", columns, "scan columns");
  app.add_flag("--unknown-focal", unknown_focal, "search the field of view instead of giving the intrinsics");
  app.add_flag("--pumpa", pumpa, "pumpA's photo against its hand-picked pairs");
  app.add_flag("-v,--verbose", verbose, "one line per case (--pumpa: the trace of each step)");
  app.add_option("--out", out_path, "markdown table to write");
  AutoResectionOptions options;
  app.add_option("--pixels-per-cell", options.pixels_per_cell, "AutoResectionOptions::pixels_per_cell");
  app.add_option("--features", options.features, "AutoResectionOptions::features");
  app.add_option("--ratio", options.ratio, "AutoResectionOptions::ratio");
  app.add_option("--rounds", options.rounds, "AutoResectionOptions::rounds");
  app.add_option("--threshold", options.ransac_threshold_px, "AutoResectionOptions::ransac_threshold_px");
  app.add_option("--min-share", options.min_inlier_share, "AutoResectionOptions::min_inlier_share");
  app.add_option("--patch", options.patch_px, "AutoResectionOptions::patch_px");
  app.add_option("--patch-step", options.patch_step_px, "AutoResectionOptions::patch_step_px");
  app.add_option("--dump", dump_dir, "folder to write each case's photo and scan colours into");
  CLI11_PARSE(app, argc, argv);
  cv::setNumThreads(threads);
  if (pumpa) return RunPumpA(options, unknown_focal, rough_offset_m, rough_turn_deg, verbose);

  std::vector<double> centre_cm, angle_deg, rms_px, share, seconds;
  int succeeded = 0, refused = 0;
  std::string rows_text;
  for (int seed = first_seed; seed < first_seed + seeds; ++seed) {
    const testing_auto_resection::AutoCase c = testing_auto_resection::MakeAutoCase(seed, rows, columns);
    const Scan scan = test_scenes::ScanScene(c.scene);
    const Photo photo = testing_auto_resection::AutoCasePhoto(c);
    std::optional<PinholeCamera> intrinsics;
    if (!unknown_focal) intrinsics = c.camera;
    if (!dump_dir.empty()) {
      WriteImage(fmt::format("{}/{}_photo.png", dump_dir, seed), photo.image);
      WriteImage(fmt::format("{}/{}_scan.png", dump_dir, seed), scan.color);
    }
    const auto start = std::chrono::steady_clock::now();
    std::string line;
    try {
      const AutoResectionResult result = AutoResection(scan, photo.image, options, intrinsics);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double dc = 100 * (result.camera.center_in_world() - c.camera.center_in_world()).norm();
      const double da = AngleDeg(result.camera.world_from_camera, c.camera.world_from_camera);
      const bool ok = dc <= 2 && da <= 0.1;
      succeeded += ok;
      centre_cm.push_back(dc), angle_deg.push_back(da), rms_px.push_back(result.rms_px);
      share.push_back(result.inlier_share), seconds.push_back(s);
      line = fmt::format("| {} | {:.2f} | {} | {:.2f} | {:.3f} | {:.2f} | {}/{} | {:.0f} % | {:.1f} | {} |",
                         seed, c.offset_m, ok ? "yes" : "no", dc, da, result.rms_px, result.inliers,
                         result.pairs.size(), 100 * result.inlier_share, s, result.rounds);
      if (verbose) line += " " + result.trace;
      if (unknown_focal) line += fmt::format(" f {:.1f} (true {:.1f})", result.camera.fx_px, c.camera.fx_px);
    } catch (const InputError& e) {
      ++refused;
      line = fmt::format("| {} | {:.2f} | refused | | | | | | | | {}", seed, c.offset_m, e.what());
    }
    if (verbose) fmt::print("{}\n", line);
    rows_text += line + "\n";
  }
  const auto summary = [](std::vector<double> v, int decimals) {
    std::sort(v.begin(), v.end());
    double mean = 0;
    for (double x : v) mean += x / v.size();
    return fmt::format("{:.{}f} / {:.{}f} / {:.{}f} / {:.{}f}", mean, decimals, Percentile(v, 5), decimals,
                       Percentile(v, 95), decimals, v.empty() ? NAN : v.back(), decimals);
  };
  std::string text = fmt::format(
      "cases {} (seeds {}-{}), {} intrinsics, scan {} x {}, {} OpenCV thread(s)\n\n"
      "| succeeded (centre <= 2 cm and angle <= 0.1°) | refused | centre error cm (mean / p5 / p95 / worst) "
      "| "
      "angle error ° (mean / p5 / p95 / worst) | RMS px (mean / p5 / p95 / worst) | inlier share | s per "
      "case |\n"
      "|---|---|---|---|---|---|---|\n"
      "| {}/{} ({:.0f} %) | {} | {} | {} | {} | {} | {} |\n\n"
      "| seed | offset m | ok | centre cm | angle ° | RMS px | inliers | share | s | rounds |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n{}",
      seeds, first_seed, first_seed + seeds - 1, unknown_focal ? "searched" : "known", rows, columns, threads,
      succeeded, seeds, 100.0 * succeeded / seeds, refused, summary(centre_cm, 2), summary(angle_deg, 3),
      summary(rms_px, 2), summary(share, 2), summary(seconds, 1), rows_text);
  fmt::print("{}", text);
  if (!out_path.empty()) std::ofstream(out_path) << text;
  return 0;
}
