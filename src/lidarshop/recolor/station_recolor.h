// Colouring a scan from every photo of its station (issue 32 item 3, the core): the E57 file's own images
// (io/e57_image_camera.h) or any photos with cameras of any model (geometry/camera_model.h).
//
// Per valid cell, the photos that see it (the occlusion test of recolor/recolor.h, per photo), and of those
// the best one by score = cos(viewing angle) · min(1, distance to the image border / border_px) / distance,
// the viewing angle taken against the cell's normal when the scan has normals (else 1): a photo that sees
// the surface squarely, near, and away from its border wins.
//
// Exposure: each photo i > 0 gets a gain per channel, g_i,c, relative to photo 0 (g_0 = 1), fitted in the
// log domain by least squares on the overlaps: for every cell seen by two photos i, j, and for every pair of
// 4-neighbour cells coloured by different photos (photos that do not overlap, like a cube map's faces, still
// meet there), log(v_i / g_i) = log(v_j / g_j) for each channel with both values in [8, 247] (not dark, not
// saturated). Colours come out at photo 0's exposure: v / g. Photos no constraint reaches keep gain 1.
//
// Seams (recolor/seam_blend.h): where the chosen photo changes between 4-neighbour cells, the cells within
// `seam_band_cells` of the change are solved again in the gradient domain (Poisson, on the scan's grid): the
// guidance across an edge is the colour difference a photo that sees both cells shows there (the average of
// both photos' when both do), else — a cube map's faces do not overlap — 0 on a continuous surface and the
// colours' own step across a depth jump (more than `seam_depth_jump_m` + 2 % of the range apart).
//
// Not done here: white balance beyond the per-channel gain.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera_model.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct CameraPhoto {
  cv::Mat image;  // CV_8UC3 RGB of the camera's size
  Camera camera;  // world frame
};

struct PhotosRecolorOptions {
  // The occlusion test (recolor/recolor.h). Without the edge guard: a station's cameras are calibrated with
  // the scanner, so a point by an occluding edge is not in doubt the way it is with a resected photo, and
  // with the guard a single panorama left 4 % of the points uncoloured (station_recolor_test).
  RecolorOptions visibility = [] {
    RecolorOptions options;
    options.edge_guard = false;
    return options;
  }();
  double border_px = 16;            // pixels: closer to the border than this lowers a photo's score
  bool equalize_exposure = true;    // fit and divide by the gains (false: the naive colours)
  bool blend_seams = true;          // gradient-domain blending of the seams between photos
  int seam_band_cells = 12;         // cells each side of a seam solved again; >= 1
  double seam_depth_jump_m = 0.05;  // a seam edge whose ranges differ by this + 2 % keeps its step
  // The naive choice (the baseline of the evaluation): the photo whose camera is nearest the point, ties to
  // the lowest index; no viewing angle, no border distance.
  bool nearest_photo = false;
  void Check() const;  // throws OptionsError
};

struct PhotosRecolorResult {
  Scan scan;                     // a clone of the input with `color` set where a photo saw the cell
  cv::Mat photo_index;           // CV_16U rows x cols: 1 + the photo that coloured the cell, 0 for none
  std::vector<cv::Vec3d> gains;  // per photo, RGB, relative to photo 0
  int64_t returns = 0;           // valid cells
  int64_t coloured = 0;          // valid cells some photo saw
  int64_t constraints = 0;       // overlap pairs used to fit the gains
  int64_t seam_edges = 0;        // 4-neighbour pairs of coloured cells coloured by different photos
  int64_t blended = 0;           // cells solved again by the seam blending
  // Wall clock, seconds: the occlusion scene (scan mesh and skirts), every photo's visibility and samples, the
  // seam blending (guidance and Poisson).
  double scene_seconds = 0, visibility_seconds = 0, blend_seconds = 0;
  // The phases in finer detail (wall clock, seconds): of visibility_seconds, the z-buffers (rasterization
  // and erosion) and the projection of the scan's cells into each photo with their occlusion tests; the
  // choice of each cell's photo (samples gathered per cell); the gain fit; the corrected colours of the chosen
  // photos; the output scan (clone and colours written); and the whole call (checks included).
  double zbuffer_seconds = 0, projection_seconds = 0, choice_seconds = 0, gain_seconds = 0,
         colour_seconds = 0, output_seconds = 0, total_seconds = 0;
  // The process's CPU time (every thread, user + system) during the call: on a shared machine, where the wall
  // clock depends on the load, the measure of the work done.
  double cpu_seconds = 0;
  std::string Summary() const;  // one line
};

// A photo that coloured the scan (`lidarshop recolor --json`'s "photos"). Described.
struct RecolorPhotoUsed {
  int index = 0;             // the images2D index (--from-e57-images) or the --photo's position
  std::string name;          // the images2D entry's name or the photo's path
  std::string model;         // the camera model's name (geometry/camera_model.h)
  std::vector<double> gain;  // RGB exposure gain relative to photo 0 (PhotosRecolorResult::gains)
};
template <>
const StructInfo& InfoOf<RecolorPhotoUsed>();

// An images2D entry left out of a station's colouring, and why ("skipped"). Described.
struct RecolorPhotoSkipped {
  int index = 0;  // the images2D index
  std::string name;
  std::string why;
};
template <>
const StructInfo& InfoOf<RecolorPhotoSkipped>();

// Wall clock per phase, seconds (issue 32 item 6): "colour" is RecolorFromPhotos as a whole, the others after
// it its parts (PhotosRecolorResult's *_seconds); "read" and "write" the caller's file input and output;
// "colour_cpu" the process's CPU time during the colouring (every thread). Described.
struct PhotosRecolorSeconds {
  double read = 0, colour = 0, write = 0, scene = 0, visibility = 0, zbuffer = 0, projection = 0, choice = 0,
         gains = 0, colours = 0, blend = 0, output = 0, colour_cpu = 0;
};
template <>
const StructInfo& InfoOf<PhotosRecolorSeconds>();

// A recolouring from several photos in brief: the result of `lidarshop recolor --json` with
// --from-e57-images or several --photo, in its order. Described.
struct PhotosRecolorSummary {
  int64_t returns = 0, coloured = 0, constraints = 0, seam_edges = 0, blended = 0;  // PhotosRecolorResult's
  std::vector<RecolorPhotoUsed> photos;                                             // in the photos' order
  std::vector<RecolorPhotoSkipped> skipped;
  PhotosRecolorSeconds seconds;
};
template <>
const StructInfo& InfoOf<PhotosRecolorSummary>();
// `photos`: one per photo given to RecolorFromPhotos, their gains filled in here; `seconds.read` and
// `seconds.write` stay 0 for the caller.
PhotosRecolorSummary SummarizePhotosRecolor(const PhotosRecolorResult& result,
                                            std::vector<RecolorPhotoUsed> photos,
                                            std::vector<RecolorPhotoSkipped> skipped);

// Throws InputError when a photo's image does not match its camera (naming the photo's index).
PhotosRecolorResult RecolorFromPhotos(const Scan& scan, const std::vector<CameraPhoto>& photos,
                                      const PhotosRecolorOptions& options = {});

// The photos of an E57 file that can colour its scan `scan_index` (`recolor --from-e57-images`): every
// images2D entry that belongs to that scan (or to none), decodes, and holds a camera model
// (io/e57_image_camera.h). The others are listed with the reason.
struct E57StationPhotos {
  std::vector<CameraPhoto> photos;
  std::vector<int> image_index;  // per photo, its images2D index
  struct Skipped {
    int image_index = 0;
    std::string why;
  };
  std::vector<Skipped> skipped;
};
E57StationPhotos StationPhotosOfE57(const E57File& file, int scan_index);

}  // namespace lidarshop
