#include "lidarshop/verify/kernel_grid.h"

#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

namespace lidarshop {

void PointColumns::Assign(std::span<const Eigen::Vector3f> points) {
  x.resize(points.size());
  y.resize(points.size());
  z.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    x[i] = points[i].x();
    y[i] = points[i].y();
    z[i] = points[i].z();
  }
}

namespace verify_internal {
namespace {

// Integer cell coordinates of a point, clamped to the grid (clamping in float first makes the truncating cast
// a floor). Building and querying use this same function, so they agree on every point's cell.
Eigen::Vector3i CellCoords(const PointCellGrid& grid, const Eigen::Vector3f& p) {
  const Eigen::Vector3f cell = (p - grid.origin_in_model) / grid.cell_m;
  return Eigen::Vector3i(static_cast<int>(std::clamp(cell.x(), 0.0f, static_cast<float>(grid.dims.x() - 1))),
                         static_cast<int>(std::clamp(cell.y(), 0.0f, static_cast<float>(grid.dims.y() - 1))),
                         static_cast<int>(std::clamp(cell.z(), 0.0f, static_cast<float>(grid.dims.z() - 1))));
}

uint32_t CellIndex(const PointCellGrid& grid, const Eigen::Vector3i& c) {
  return static_cast<uint32_t>((static_cast<int64_t>(c.z()) * grid.dims.y() + c.y()) * grid.dims.x() + c.x());
}

PointCellGrid BuildCellGrid(std::span<const Eigen::Vector3f> points, const Eigen::Vector3f& lo,
                            const Eigen::Vector3f& extent, float radius) {
  PointCellGrid grid;
  grid.radius_m = radius;
  grid.origin_in_model = lo;
  // Larger cells only add candidates, so a cap on the cell count keeps huge models (or tiny radii) in memory.
  constexpr double kMaxCells = 2e6;
  grid.cell_m = std::max(radius * 1.001f, static_cast<float>(std::cbrt(extent.prod() / kMaxCells)));
  for (int k = 0; k < 3; ++k)
    grid.dims[k] = std::max(1, static_cast<int>(std::ceil(extent[k] / grid.cell_m)));
  const int64_t cells = static_cast<int64_t>(grid.dims.x()) * grid.dims.y() * grid.dims.z();
  // Counting sort by cell, stable: ascending point index within a cell.
  std::vector<uint32_t> cell_of(points.size());
  grid.offsets.assign(cells + 1, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    cell_of[i] = CellIndex(grid, CellCoords(grid, points[i]));
    ++grid.offsets[cell_of[i] + 1];
  }
  for (int64_t c = 0; c < cells; ++c) grid.offsets[c + 1] += grid.offsets[c];
  std::vector<uint32_t> next(grid.offsets.begin(), grid.offsets.end() - 1);
  grid.indices.resize(points.size());
  std::vector<Eigen::Vector3f> sorted(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const uint32_t slot = next[cell_of[i]]++;
    grid.indices[slot] = static_cast<uint32_t>(i);
    sorted[slot] = points[i];
  }
  grid.positions.Assign(sorted);
  return grid;
}

// The runs [begin, end) of the sorted points in the 3 x 3 x 3 cells around p's own cell: nine runs of three
// cells contiguous in x (fewer at the grid's border). Returns the number of runs.
struct Run {
  uint32_t begin, end;
};
inline int NeighbourRuns(const PointCellGrid& grid, const Eigen::Vector3i& c, Run runs[9]) {
  const int x0 = std::max(c.x() - 1, 0), x1 = std::min(c.x() + 1, grid.dims.x() - 1);
  int count = 0;
  for (int z = std::max(c.z() - 1, 0); z <= std::min(c.z() + 1, grid.dims.z() - 1); ++z) {
    for (int y = std::max(c.y() - 1, 0); y <= std::min(c.y() + 1, grid.dims.y() - 1); ++y) {
      const int64_t row = (static_cast<int64_t>(z) * grid.dims.y() + y) * grid.dims.x();
      runs[count++] = {grid.offsets[row + x0], grid.offsets[row + x1 + 1]};
    }
  }
  return count;
}

// d² in the order both paths use: (dx² + dy²) + dz², no fused multiply-add.
inline float SquaredDistance(const PointColumns& points, uint32_t k, const Eigen::Vector3f& p) {
  const float dx = points.x[k] - p.x(), dy = points.y[k] - p.y(), dz = points.z[k] - p.z();
  return (dx * dx + dy * dy) + dz * dz;
}

// The queries grouped by cell: a stable LSD radix sort of the query indices by cell index (11 bits per pass;
// a few thousand queries fall into a few hundred cells, so each cell's candidates are gathered once for ~20
// queries). The order is deterministic and both paths use it.
struct CellGroups {
  std::vector<uint32_t> order, cell;  // query indices sorted by cell; the cell of each sorted query
  std::vector<uint32_t> order_tmp, cell_tmp;

  void Sort(const PointCellGrid& grid, std::span<const Eigen::Vector3f> points) {
    const size_t n = points.size();
    order.resize(n), cell.resize(n), order_tmp.resize(n), cell_tmp.resize(n);
    for (size_t j = 0; j < n; ++j) {
      order[j] = static_cast<uint32_t>(j);
      cell[j] = CellIndex(grid, CellCoords(grid, points[j]));
    }
    const uint64_t cells = static_cast<uint64_t>(grid.dims.x()) * grid.dims.y() * grid.dims.z();
    constexpr int kBits = 11;
    uint32_t count[1u << kBits];
    for (int shift = 0; (cells - 1) >> shift != 0; shift += kBits) {
      std::fill(std::begin(count), std::end(count), 0u);
      for (size_t j = 0; j < n; ++j) ++count[(cell[j] >> shift) & ((1u << kBits) - 1)];
      uint32_t total = 0;
      for (uint32_t& c : count) total += std::exchange(c, total);
      for (size_t j = 0; j < n; ++j) {
        const uint32_t slot = count[(cell[j] >> shift) & ((1u << kBits) - 1)]++;
        order_tmp[slot] = order[j];
        cell_tmp[slot] = cell[j];
      }
      order.swap(order_tmp);
      cell.swap(cell_tmp);
    }
  }
  // The end of the group of sorted queries from `begin` that share its cell.
  size_t GroupEnd(size_t begin) const {
    size_t end = begin + 1;
    while (end < cell.size() && cell[end] == cell[begin]) ++end;
    return end;
  }
};

Eigen::Vector3i CellFromIndex(const PointCellGrid& grid, uint32_t index) {
  return Eigen::Vector3i(static_cast<int>(index % grid.dims.x()),
                         static_cast<int>((index / grid.dims.x()) % grid.dims.y()),
                         static_cast<int>(index / (static_cast<uint32_t>(grid.dims.x()) * grid.dims.y())));
}

void AccumulateGroupScalar(const PointCellGrid& grid, const Run* runs, int num_runs,
                           std::span<const Eigen::Vector3f> points, const uint32_t* group, size_t group_size,
                           float radius_sq, float inverse_two_sigma_sq, float* sum, float* closest_sq) {
  for (size_t g = 0; g < group_size; ++g) {
    const Eigen::Vector3f& p = points[group[g]];
    float closest = std::numeric_limits<float>::infinity();
    for (int run = 0; run < num_runs; ++run) {
      for (uint32_t k = runs[run].begin; k < runs[run].end; ++k) {
        const float distance_sq = SquaredDistance(grid.positions, k, p);
        if (!(distance_sq < radius_sq)) continue;
        closest = std::min(closest, distance_sq);
        // Only min(1, sum) is used: a saturated point needs no more exp (exact, and most of the cost).
        if (sum[k] < 1.0f) sum[k] += KernelExp(-distance_sq * inverse_two_sigma_sq);
      }
    }
    closest_sq[group[g]] = closest;
  }
}

void NearestGroupScalar(const PointCellGrid& grid, const Run* runs, int num_runs,
                        std::span<const Eigen::Vector3f> points, const uint32_t* group, size_t group_size,
                        float* closest_sq) {
  for (size_t g = 0; g < group_size; ++g) {
    const Eigen::Vector3f& p = points[group[g]];
    float closest = std::numeric_limits<float>::infinity();
    for (int run = 0; run < num_runs; ++run) {
      for (uint32_t k = runs[run].begin; k < runs[run].end; ++k) {
        closest = std::min(closest, SquaredDistance(grid.positions, k, p));
      }
    }
    closest_sq[group[g]] = closest;
  }
}

// The candidates of one 3 x 3 x 3 neighbourhood that can matter to a group of queries, copied into one
// contiguous, 8-padded block (with their sums): the nine short runs (seven points each on average: mostly
// partial vectors and mispredicted loop exits) become one straight loop for all the queries of the cell, and
// the candidates farther than the radius from the group's bounding box (more than half of them) are dropped.
struct CandidateBlock {
  std::vector<float> x, y, z, sum;
  std::vector<uint32_t> slot;
  size_t count = 0;

  size_t padded_count() const { return (count + 7) / 8 * 8; }
  void Store(float* global_sum) const {
    for (size_t m = 0; m < count; ++m) global_sum[slot[m]] = sum[m];
  }
};

// Fills `block` from the runs, keeping the candidates within `radius` of the group's bounding box (a little
// slack keeps float rounding on the safe side): 8 candidates per step, kept lanes packed to the left.
__attribute__((target("avx2"))) void LoadBlockAvx2(const PointCellGrid& grid, const Run* runs, int num_runs,
                                                   const float* global_sum,
                                                   std::span<const Eigen::Vector3f> points,
                                                   const uint32_t* group, size_t group_size, float radius,
                                                   CandidateBlock& block) {
  Eigen::AlignedBox3f box;
  for (size_t g = 0; g < group_size; ++g) box.extend(points[group[g]]);
  size_t total = 0;
  for (int run = 0; run < num_runs; ++run) total += runs[run].end - runs[run].begin;
  if (block.x.size() < total + 8) {  // + 8: every step stores a whole vector at the current count
    for (auto* column : {&block.x, &block.y, &block.z, &block.sum}) column->resize(total + 8);
    block.slot.resize(total + 8);
  }
  const __m256 reach_sq = _mm256_set1_ps(radius * radius * 1.0001f + 1e-12f);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 lo_x = _mm256_set1_ps(box.min().x()), lo_y = _mm256_set1_ps(box.min().y()),
               lo_z = _mm256_set1_ps(box.min().z());
  const __m256 hi_x = _mm256_set1_ps(box.max().x()), hi_y = _mm256_set1_ps(box.max().y()),
               hi_z = _mm256_set1_ps(box.max().z());
  const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  size_t count = 0;
  for (int run = 0; run < num_runs; ++run) {
    for (uint32_t k = runs[run].begin; k < runs[run].end; k += 8) {
      // Masked loads: lanes past the run read nothing (no padding needed, no fault at the array's end).
      const __m256i in_run =
          _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(runs[run].end - k)), lane_index);
      const __m256 x = _mm256_maskload_ps(grid.positions.x.data() + k, in_run);
      const __m256 y = _mm256_maskload_ps(grid.positions.y.data() + k, in_run);
      const __m256 z = _mm256_maskload_ps(grid.positions.z.data() + k, in_run);
      const __m256 ex = _mm256_max_ps(_mm256_max_ps(_mm256_sub_ps(lo_x, x), _mm256_sub_ps(x, hi_x)), zero);
      const __m256 ey = _mm256_max_ps(_mm256_max_ps(_mm256_sub_ps(lo_y, y), _mm256_sub_ps(y, hi_y)), zero);
      const __m256 ez = _mm256_max_ps(_mm256_max_ps(_mm256_sub_ps(lo_z, z), _mm256_sub_ps(z, hi_z)), zero);
      const __m256 gap_sq =
          _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey)), _mm256_mul_ps(ez, ez));
      const unsigned keep = static_cast<unsigned>(_mm256_movemask_ps(
          _mm256_and_ps(_mm256_cmp_ps(gap_sq, reach_sq, _CMP_LE_OQ), _mm256_castsi256_ps(in_run))));
      const __m256i pack =
          _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(kLeftPack.lanes[keep])));
      _mm256_storeu_ps(block.x.data() + count, _mm256_permutevar8x32_ps(x, pack));
      _mm256_storeu_ps(block.y.data() + count, _mm256_permutevar8x32_ps(y, pack));
      _mm256_storeu_ps(block.z.data() + count, _mm256_permutevar8x32_ps(z, pack));
      const __m256 sum = global_sum != nullptr ? _mm256_maskload_ps(global_sum + k, in_run) : zero;
      _mm256_storeu_ps(block.sum.data() + count, _mm256_permutevar8x32_ps(sum, pack));
      const __m256i slot = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(k)), lane_index);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(block.slot.data() + count),
                          _mm256_permutevar8x32_epi32(slot, pack));
      count += std::popcount(keep);
    }
  }
  block.count = count;
  for (size_t m = count; m < block.padded_count(); ++m) {  // never inside any radius, never updated
    block.x[m] = block.y[m] = block.z[m] = 1e18f;          // (finite: differences stay finite)
    block.sum[m] = 1.0f;
  }
}

// The minimum does not depend on the order, so this equals the scalar paths' running minimum bit for bit.
__attribute__((target("avx2"), always_inline)) inline float HorizontalMin(__m256 values) {
  __m128 m = _mm_min_ps(_mm256_castps256_ps128(values), _mm256_extractf128_ps(values, 1));
  m = _mm_min_ps(m, _mm_movehl_ps(m, m));
  m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}

// KernelExp, 8 at a time (the same operations in the same order).
__attribute__((target("avx2"), always_inline)) inline __m256 KernelExp8(__m256 x) {
  x = _mm256_max_ps(x, _mm256_set1_ps(-87.0f));
  const __m256 n = _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(1.44269504f)),
                                   _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  const __m256 r = _mm256_sub_ps(_mm256_sub_ps(x, _mm256_mul_ps(n, _mm256_set1_ps(0.693145751953125f))),
                                 _mm256_mul_ps(n, _mm256_set1_ps(1.42860682030941723212e-6f)));
  const __m256 r2 = _mm256_mul_ps(r, r), r4 = _mm256_mul_ps(r2, r2);
  const __m256 low = _mm256_add_ps(
      _mm256_add_ps(_mm256_set1_ps(1.0f), r),
      _mm256_mul_ps(r2, _mm256_add_ps(_mm256_set1_ps(0.5f), _mm256_mul_ps(r, _mm256_set1_ps(1.0f / 6.0f)))));
  const __m256 high = _mm256_add_ps(
      _mm256_add_ps(_mm256_set1_ps(1.0f / 24.0f), _mm256_mul_ps(r, _mm256_set1_ps(1.0f / 120.0f))),
      _mm256_mul_ps(r2, _mm256_add_ps(_mm256_set1_ps(1.0f / 720.0f),
                                      _mm256_mul_ps(r, _mm256_set1_ps(1.0f / 5040.0f)))));
  const __m256 p = _mm256_add_ps(low, _mm256_mul_ps(r4, high));
  const __m256i scale =
      _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(n), _mm256_set1_epi32(127)), 23);
  return _mm256_mul_ps(p, _mm256_castsi256_ps(scale));
}

// d² of 8 candidates in the scalar order: (dx² + dy²) + dz², no fused multiply-add.
__attribute__((target("avx2"), always_inline)) inline __m256 SquaredDistance8(const CandidateBlock& block,
                                                                              size_t m,
                                                                              const Eigen::Vector3f& p) {
  const __m256 dx = _mm256_sub_ps(_mm256_loadu_ps(block.x.data() + m), _mm256_set1_ps(p.x()));
  const __m256 dy = _mm256_sub_ps(_mm256_loadu_ps(block.y.data() + m), _mm256_set1_ps(p.y()));
  const __m256 dz = _mm256_sub_ps(_mm256_loadu_ps(block.z.data() + m), _mm256_set1_ps(p.z()));
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
}

// AccumulateGroupScalar 8 candidates at a time. The block's sums sit beside its positions, so one vector
// compare tells which of the 8 still need an exp: after the first scene points of a region nearly all are
// saturated, and the hit test, the closest distance and the saturation test stay in vector registers.
__attribute__((target("avx2"))) void AccumulateGroupAvx2(const PointCellGrid& grid, const Run* runs,
                                                         int num_runs,
                                                         std::span<const Eigen::Vector3f> points,
                                                         const uint32_t* group, size_t group_size,
                                                         float radius_sq, float inverse_two_sigma_sq,
                                                         float* sum, float* closest_sq) {
  thread_local CandidateBlock block;
  LoadBlockAvx2(grid, runs, num_runs, sum, points, group, group_size, std::sqrt(radius_sq), block);
  const size_t candidates = block.padded_count();
  const __m256 radius_sq8 = _mm256_set1_ps(radius_sq);
  const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
  const __m256 inverse_two_sigma_sq8 = _mm256_set1_ps(inverse_two_sigma_sq);
  const __m256 infinity = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  for (size_t g = 0; g < group_size; ++g) {
    const Eigen::Vector3f& p = points[group[g]];
    __m256 closest = infinity;
    for (size_t m = 0; m < candidates; m += 8) {
      const __m256 d2 = SquaredDistance8(block, m, p);
      const __m256 inside = _mm256_cmp_ps(d2, radius_sq8, _CMP_LT_OQ);
      closest = _mm256_min_ps(closest, _mm256_blendv_ps(infinity, d2, inside));
      const __m256 sum8 = _mm256_loadu_ps(block.sum.data() + m);
      const __m256 update = _mm256_and_ps(inside, _mm256_cmp_ps(sum8, one, _CMP_LT_OQ));
      if (_mm256_testz_ps(update, update)) continue;
      // + 0 in the lanes not updated leaves their sums exactly as they are.
      const __m256 weight = KernelExp8(_mm256_mul_ps(_mm256_sub_ps(zero, d2), inverse_two_sigma_sq8));
      _mm256_storeu_ps(block.sum.data() + m, _mm256_add_ps(sum8, _mm256_and_ps(weight, update)));
    }
    closest_sq[group[g]] = HorizontalMin(closest);
  }
  block.Store(sum);
}

__attribute__((target("avx2"))) void NearestGroupAvx2(const PointCellGrid& grid, const Run* runs,
                                                      int num_runs, std::span<const Eigen::Vector3f> points,
                                                      const uint32_t* group, size_t group_size,
                                                      float* closest_sq) {
  thread_local CandidateBlock block;
  LoadBlockAvx2(grid, runs, num_runs, nullptr, points, group, group_size, grid.radius_m, block);
  const size_t candidates = block.padded_count();
  for (size_t g = 0; g < group_size; ++g) {
    const Eigen::Vector3f& p = points[group[g]];
    __m256 closest = _mm256_set1_ps(std::numeric_limits<float>::infinity());
    for (size_t m = 0; m < candidates; m += 8)
      closest = _mm256_min_ps(closest, SquaredDistance8(block, m, p));
    closest_sq[group[g]] = HorizontalMin(closest);
  }
}

}  // namespace

KernelNeighbourGrid BuildKernelGrid(std::span<const Eigen::Vector3f> points,
                                    const Eigen::AlignedBox3f& bounds, float kernel_radius, float trim) {
  const float reach = std::max(kernel_radius, trim);
  const Eigen::Vector3f lo = bounds.min().array() - reach;
  const Eigen::Vector3f extent = bounds.sizes().array() + 2 * reach;
  KernelNeighbourGrid grid;
  grid.kernel = BuildCellGrid(points, lo, extent, kernel_radius);
  grid.icp = BuildCellGrid(points, lo, extent, trim);
  return grid;
}

namespace {

// Calls group_step(runs, num_runs, group, group_size) for each group of the
// points that share a cell of `grid`.
template <typename GroupStep>
void ForEachCellGroup(const PointCellGrid& grid, std::span<const Eigen::Vector3f> points,
                      GroupStep&& group_step) {
  thread_local CellGroups groups;
  groups.Sort(grid, points);
  for (size_t begin = 0; begin < points.size();) {
    const size_t end = groups.GroupEnd(begin);
    Run runs[9];
    const int num_runs = NeighbourRuns(grid, CellFromIndex(grid, groups.cell[begin]), runs);
    group_step(runs, num_runs, groups.order.data() + begin, end - begin);
    begin = end;
  }
}

}  // namespace

void AccumulateKernel(const KernelNeighbourGrid& grid, std::span<const Eigen::Vector3f> points,
                      float radius_sq, float inverse_two_sigma_sq, float* sum, float* closest_sq,
                      SimdPath path) {
  const auto group_step = path == SimdPath::kAvx2 && BestSimdPath() == SimdPath::kAvx2
                              ? AccumulateGroupAvx2
                              : AccumulateGroupScalar;
  ForEachCellGroup(grid.kernel, points,
                   [&](const Run* runs, int num_runs, const uint32_t* group, size_t size) {
                     group_step(grid.kernel, runs, num_runs, points, group, size, radius_sq,
                                inverse_two_sigma_sq, sum, closest_sq);
                   });
}

void NearestSquaredDistance(const KernelNeighbourGrid& grid, std::span<const Eigen::Vector3f> points,
                            float* closest_sq, SimdPath path) {
  const auto group_step =
      path == SimdPath::kAvx2 && BestSimdPath() == SimdPath::kAvx2 ? NearestGroupAvx2 : NearestGroupScalar;
  ForEachCellGroup(grid.icp, points, [&](const Run* runs, int num_runs, const uint32_t* group, size_t size) {
    group_step(grid.icp, runs, num_runs, points, group, size, closest_sq);
  });
}

}  // namespace verify_internal
}  // namespace lidarshop
