#include "lidarshop/verify/footprint_gather.h"

#include <immintrin.h>

#include <algorithm>
#include <bit>

namespace lidarshop::verify_internal {
namespace {

constexpr int kBandRows = 4;  // PreparedScan::kBandRows (checked in verify.cc)

// One cell, in the operation order the AVX2 path uses (no fused multiply-add, same min/max nesting).
void GatherCell(const Eigen::Vector4f& cell, uint32_t cell_index, bool in_rows, const GatherFrame& frame,
                FootprintRays& rays, NearPoints& near) {
  const Eigen::Matrix3f& m = frame.linear;
  const Eigen::Vector3f& o = frame.origin;
  const float range = cell.w();
  const bool returned = in_rows && range > 0;
  float p[3], inverse[3];
  for (int i = 0; i < 3; ++i) {
    p[i] = ((m(i, 0) * cell.x() + m(i, 1) * cell.y()) + m(i, 2) * cell.z()) + o[i];
  }
  float direction[3], t_min[3], t_max[3];
  for (int i = 0; i < 3; ++i) {
    direction[i] = (p[i] - o[i]) / range;
    inverse[i] = 1.0f / direction[i];
    const float t_lo = (frame.model_box.min()[i] - o[i]) * inverse[i];
    const float t_hi = (frame.model_box.max()[i] - o[i]) * inverse[i];
    // _mm256_min_ps / _mm256_max_ps semantics: the second operand when the first compare fails.
    t_min[i] = t_lo < t_hi ? t_lo : t_hi;
    t_max[i] = t_lo > t_hi ? t_lo : t_hi;
  }
  auto max_of = [](float a, float b) { return a > b ? a : b; };
  auto min_of = [](float a, float b) { return a < b ? a : b; };
  const float t0 = max_of(max_of(t_min[0], t_min[1]), t_min[2]);
  const float t1 = min_of(min_of(t_max[0], t_max[1]), t_max[2]);
  const size_t k = rays.size;
  rays.dir_x[k] = direction[0], rays.dir_y[k] = direction[1], rays.dir_z[k] = direction[2];
  rays.t_near[k] = max_of(t0 - 1e-4f * (1.0f + t0), 0.0f);  // slack: the box is float-rounded too
  rays.limit[k] = range - frame.allowance;
  rays.cell[k] = cell_index;
  // Written so that a NaN (0 · inf: the origin on a face plane) keeps the ray; Embree decides.
  rays.size += returned && !(t0 > t1) && !(t1 < 0);
  const size_t j = near.size;
  near.x[j] = p[0], near.y[j] = p[1], near.z[j] = p[2];
  bool inside = returned;
  for (int i = 0; i < 3; ++i)
    inside = inside && p[i] >= frame.near_box.min()[i] && p[i] <= frame.near_box.max()[i];
  near.size += inside;
}

void GatherBandScalar(const Eigen::Vector4f* cells, int band_row, int row_begin, int row_end, int first_col,
                      int num_cols, int scan_cols, const GatherFrame& frame, FootprintRays& rays,
                      NearPoints& near) {
  for (int col = 0; col < num_cols; ++col) {
    for (int row = 0; row < kBandRows; ++row) {
      const int image_row = band_row + row;
      const bool in_rows = image_row >= row_begin && image_row < row_end;
      const uint32_t cell_index =
          static_cast<uint32_t>(static_cast<int64_t>(image_row) * scan_cols + first_col + col);
      GatherCell(cells[col * kBandRows + row], cell_index, in_rows, frame, rays, near);
    }
  }
}

__attribute__((target("avx2"), always_inline)) inline void StorePacked(float* destination, __m256 values,
                                                                       __m256i pack) {
  _mm256_storeu_ps(destination, _mm256_permutevar8x32_ps(values, pack));
}

// 8 cells (two columns of the band) per step: AoS (x, y, z, range) → SoA, the scalar arithmetic lane by
// lane, kept lanes left-packed into the outputs.
__attribute__((target("avx2"))) void GatherBandAvx2(const Eigen::Vector4f* cells, int band_row, int row_begin,
                                                    int row_end, int first_col, int num_cols, int scan_cols,
                                                    const GatherFrame& frame, FootprintRays& rays,
                                                    NearPoints& near) {
  const Eigen::Matrix3f& m = frame.linear;
  const Eigen::Vector3f& o = frame.origin;
  __m256 linear[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) linear[i][j] = _mm256_set1_ps(m(i, j));
  }
  const __m256 origin[3] = {_mm256_set1_ps(o.x()), _mm256_set1_ps(o.y()), _mm256_set1_ps(o.z())};
  __m256 box_lo[3], box_hi[3], near_lo[3], near_hi[3];
  for (int i = 0; i < 3; ++i) {
    box_lo[i] = _mm256_set1_ps(frame.model_box.min()[i]);
    box_hi[i] = _mm256_set1_ps(frame.model_box.max()[i]);
    near_lo[i] = _mm256_set1_ps(frame.near_box.min()[i]);
    near_hi[i] = _mm256_set1_ps(frame.near_box.max()[i]);
  }
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), slack = _mm256_set1_ps(1e-4f);
  const __m256 allowance = _mm256_set1_ps(frame.allowance);
  // Lane l is the cell (column l / 4, row l % 4) of the step.
  const __m256i lane_row = _mm256_setr_epi32(0, 1, 2, 3, 0, 1, 2, 3);
  const __m256i lane_col = _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1);
  const __m256i image_row = _mm256_add_epi32(_mm256_set1_epi32(band_row), lane_row);
  const __m256i rows_inside =
      _mm256_and_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(row_end), image_row),
                       _mm256_cmpgt_epi32(image_row, _mm256_set1_epi32(row_begin - 1)));
  const __m256i row_offset = _mm256_mullo_epi32(image_row, _mm256_set1_epi32(scan_cols));
  // The transpose below yields lanes in the order (0, 2, 4, 6, 1, 3, 5, 7); this puts them back.
  const __m256i unshuffle = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
  for (int col = 0; col < num_cols; col += 2) {
    const float* base = cells[col * kBandRows].data();
    const bool second_column = col + 1 < num_cols;
    const __m256i second_half =
        _mm256_setr_epi32(-1, -1, -1, -1, second_column ? -1 : 0, second_column ? -1 : 0,
                          second_column ? -1 : 0, second_column ? -1 : 0);
    const __m256 a = _mm256_loadu_ps(base);
    const __m256 b = _mm256_loadu_ps(base + 8);
    const __m256 c = _mm256_maskload_ps(base + 16, second_half);
    const __m256 d = _mm256_maskload_ps(base + 24, second_half);
    const __m256 t0 = _mm256_unpacklo_ps(a, b), t1 = _mm256_unpackhi_ps(a, b);
    const __m256 t2 = _mm256_unpacklo_ps(c, d), t3 = _mm256_unpackhi_ps(c, d);
    const __m256 x = _mm256_permutevar8x32_ps(_mm256_shuffle_ps(t0, t2, 0x44), unshuffle);
    const __m256 y = _mm256_permutevar8x32_ps(_mm256_shuffle_ps(t0, t2, 0xEE), unshuffle);
    const __m256 z = _mm256_permutevar8x32_ps(_mm256_shuffle_ps(t1, t3, 0x44), unshuffle);
    const __m256 range = _mm256_permutevar8x32_ps(_mm256_shuffle_ps(t1, t3, 0xEE), unshuffle);

    const __m256i lane_in_step = _mm256_cmpgt_epi32(_mm256_set1_epi32(num_cols - col), lane_col);
    const __m256 returned = _mm256_and_ps(_mm256_castsi256_ps(_mm256_and_si256(rows_inside, lane_in_step)),
                                          _mm256_cmp_ps(range, zero, _CMP_GT_OQ));
    __m256 p[3], direction[3], t_min[3], t_max[3];
    for (int i = 0; i < 3; ++i) {
      p[i] = _mm256_add_ps(
          _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(linear[i][0], x), _mm256_mul_ps(linear[i][1], y)),
                        _mm256_mul_ps(linear[i][2], z)),
          origin[i]);
      direction[i] = _mm256_div_ps(_mm256_sub_ps(p[i], origin[i]), range);
      const __m256 inverse = _mm256_div_ps(one, direction[i]);
      const __m256 t_lo = _mm256_mul_ps(_mm256_sub_ps(box_lo[i], origin[i]), inverse);
      const __m256 t_hi = _mm256_mul_ps(_mm256_sub_ps(box_hi[i], origin[i]), inverse);
      t_min[i] = _mm256_min_ps(t_lo, t_hi);
      t_max[i] = _mm256_max_ps(t_lo, t_hi);
    }
    const __m256 enter = _mm256_max_ps(_mm256_max_ps(t_min[0], t_min[1]), t_min[2]);
    const __m256 exit = _mm256_min_ps(_mm256_min_ps(t_max[0], t_max[1]), t_max[2]);
    const __m256 meets_box = _mm256_andnot_ps(
        _mm256_or_ps(_mm256_cmp_ps(enter, exit, _CMP_GT_OQ), _mm256_cmp_ps(exit, zero, _CMP_LT_OQ)),
        returned);
    const unsigned keep_ray = static_cast<unsigned>(_mm256_movemask_ps(meets_box));
    if (keep_ray != 0) {
      const __m256i pack =
          _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(kLeftPack.lanes[keep_ray])));
      const size_t k = rays.size;
      StorePacked(rays.dir_x.data() + k, direction[0], pack);
      StorePacked(rays.dir_y.data() + k, direction[1], pack);
      StorePacked(rays.dir_z.data() + k, direction[2], pack);
      const __m256 t_near =
          _mm256_max_ps(_mm256_sub_ps(enter, _mm256_mul_ps(slack, _mm256_add_ps(one, enter))), zero);
      StorePacked(rays.t_near.data() + k, t_near, pack);
      StorePacked(rays.limit.data() + k, _mm256_sub_ps(range, allowance), pack);
      const __m256i cell =
          _mm256_add_epi32(row_offset, _mm256_add_epi32(_mm256_set1_epi32(first_col + col), lane_col));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(rays.cell.data() + k),
                          _mm256_permutevar8x32_epi32(cell, pack));
      rays.size += std::popcount(keep_ray);
    }
    __m256 inside = returned;
    for (int i = 0; i < 3; ++i) {
      inside = _mm256_and_ps(inside, _mm256_and_ps(_mm256_cmp_ps(p[i], near_lo[i], _CMP_GE_OQ),
                                                   _mm256_cmp_ps(p[i], near_hi[i], _CMP_LE_OQ)));
    }
    const unsigned keep_near = static_cast<unsigned>(_mm256_movemask_ps(inside));
    if (keep_near != 0) {
      const __m256i pack =
          _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(kLeftPack.lanes[keep_near])));
      StorePacked(near.x.data() + near.size, p[0], pack);
      StorePacked(near.y.data() + near.size, p[1], pack);
      StorePacked(near.z.data() + near.size, p[2], pack);
      near.size += std::popcount(keep_near);
    }
  }
}

}  // namespace

void ReserveGather(size_t cells, FootprintRays& rays, NearPoints& near) {
  const size_t ray_capacity = rays.size + cells + 8;
  if (rays.dir_x.size() < ray_capacity) {
    for (auto* column : {&rays.dir_x, &rays.dir_y, &rays.dir_z, &rays.t_near, &rays.limit}) {
      column->resize(ray_capacity);
    }
    rays.cell.resize(ray_capacity);
  }
  const size_t near_capacity = near.size + cells + 8;
  if (near.x.size() < near_capacity) {
    for (auto* column : {&near.x, &near.y, &near.z}) column->resize(near_capacity);
  }
}

void GatherBand(const Eigen::Vector4f* cells, int band_row, int row_begin, int row_end, int first_col,
                int num_cols, int scan_cols, const GatherFrame& frame, FootprintRays& rays, NearPoints& near,
                SimdPath path) {
  if (path == SimdPath::kAvx2 && BestSimdPath() == SimdPath::kAvx2) {
    GatherBandAvx2(cells, band_row, row_begin, row_end, first_col, num_cols, scan_cols, frame, rays, near);
  } else {
    GatherBandScalar(cells, band_row, row_begin, row_end, first_col, num_cols, scan_cols, frame, rays, near);
  }
}

}  // namespace lidarshop::verify_internal
