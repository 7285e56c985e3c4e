// Internal to the verify module: the per-cell step of VerifyPose. For the cells of a scan's angular footprint
// it moves each return into the model frame and keeps (1) the rays that meet the model's box, for the
// consistency queries, and (2) the points inside the near box, for confidence and ICP. It visits every
// footprint cell of every pose, so it runs 8 cells per AVX2 instruction with the kept lanes left-packed (no
// data-dependent branch: the silhouette's are unpredictable); the scalar path gives bit-identical output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lidarshop/verify/simd_util.h"

namespace lidarshop::verify_internal {

// Rays from one origin as columns (model frame).
struct FootprintRays {
  std::vector<float> dir_x, dir_y, dir_z;  // unit directions
  std::vector<float> t_near;               // just before the model's box (0 when the origin is inside it)
  std::vector<float> limit;                // d_s − a
  std::vector<uint32_t> cell;              // row * cols + col
  size_t size = 0;
};

// Scene points inside the near box (model frame), as columns.
struct NearPoints {
  std::vector<float> x, y, z;
  size_t size = 0;
};

struct GatherFrame {
  Eigen::Matrix3f linear;         // model_from_scanner, rotation part (may include a uniform scale)
  Eigen::Vector3f origin;         // the scanner's origin in the model frame
  Eigen::AlignedBox3f model_box;  // the model's bounds
  Eigen::AlignedBox3f near_box;   // the model's bounds grown by max(3σ, trim)
  float allowance = 0.0f;         // a, metres
};

// Makes room for `cells` more cells in both outputs (+ 8 for whole-vector stores).
void ReserveGather(size_t cells, FootprintRays& rays, NearPoints& near);

// The cells of one band (PreparedScan::band_cells layout: kBandRows cells per column, top row first) for
// the columns [first_col, first_col + num_cols) of a scan with `scan_cols` columns; `band_row` is the band's
// first image row and only its rows in [row_begin, row_end) count. `cells` points at the band's first
// column's first cell. Appends to `rays` and `near` (which ReserveGather made room for).
void GatherBand(const Eigen::Vector4f* cells, int band_row, int row_begin, int row_end, int first_col,
                int num_cols, int scan_cols, const GatherFrame& frame, FootprintRays& rays, NearPoints& near,
                SimdPath path = BestSimdPath());

}  // namespace lidarshop::verify_internal
