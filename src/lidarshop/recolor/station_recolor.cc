#include "lidarshop/recolor/station_recolor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "lidarshop/io/e57_image_camera.h"
#include "lidarshop/raycast/raycast.h"
#include "lidarshop/recolor/seam_blend.h"
#include "lidarshop/recolor/visibility.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void PhotosRecolorOptions::Check() const {
  visibility.Check();
  if (!(border_px >= 0 && border_px < 1e6))
    throw OptionsError(fmt::format("PhotosRecolorOptions.border_px must be in [0, 1e6), got {}", border_px));
  if (!(seam_band_cells >= 1 && seam_band_cells <= 1000))
    throw OptionsError(
        fmt::format("PhotosRecolorOptions.seam_band_cells must be in [1, 1000], got {}", seam_band_cells));
  if (!(seam_depth_jump_m >= 0 && seam_depth_jump_m < 1e6))
    throw OptionsError(
        fmt::format("PhotosRecolorOptions.seam_depth_jump_m must be in [0, 1e6), got {}", seam_depth_jump_m));
}

PhotosRecolorSummary SummarizePhotosRecolor(const PhotosRecolorResult& result,
                                            std::vector<RecolorPhotoUsed> photos,
                                            std::vector<RecolorPhotoSkipped> skipped) {
  PhotosRecolorSummary summary;
  summary.returns = result.returns;
  summary.coloured = result.coloured;
  summary.constraints = result.constraints;
  summary.seam_edges = result.seam_edges;
  summary.blended = result.blended;
  for (size_t i = 0; i < photos.size() && i < result.gains.size(); ++i)
    photos[i].gain = {result.gains[i][0], result.gains[i][1], result.gains[i][2]};
  summary.photos = std::move(photos);
  summary.skipped = std::move(skipped);
  PhotosRecolorSeconds& seconds = summary.seconds;
  seconds.colour = result.total_seconds;
  seconds.scene = result.scene_seconds;
  seconds.visibility = result.visibility_seconds;
  seconds.zbuffer = result.zbuffer_seconds;
  seconds.projection = result.projection_seconds;
  seconds.choice = result.choice_seconds;
  seconds.gains = result.gain_seconds;
  seconds.colours = result.colour_seconds;
  seconds.blend = result.blend_seconds;
  seconds.output = result.output_seconds;
  seconds.colour_cpu = result.cpu_seconds;
  return summary;
}

std::string PhotosRecolorResult::Summary() const {
  return fmt::format(
      "{} of {} points coloured from {} photo(s); gains fitted on {} overlap pairs; {} seam edges, {} cells "
      "blended (occlusion scene {:.2f} s, visibility {:.2f} s, blending {:.2f} s)",
      coloured, returns, gains.size(), constraints, seam_edges, blended, scene_seconds, visibility_seconds,
      blend_seconds);
}

namespace {

constexpr double kDarkest = 8, kBrightest = 247;  // values usable for the gain fit (not dark, not saturated)

struct Sample {
  int photo;
  cv::Vec3b rgb;
};

// Least squares for log gains of one channel: rows (i, j, log v_i − log v_j) mean l_i − l_j = that, l_0 = 0.
std::vector<double> FitLogGains(int photos, const std::vector<std::pair<std::pair<int, int>, double>>& rows) {
  std::vector<double> result(photos, 0.0);
  if (photos < 2 || rows.empty()) return result;
  // Normal equations over l_1..l_{n−1}, with a small ridge that keeps unreached photos at 0 (gain 1).
  const int n = photos - 1;
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(n, n) * 1e-6;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  for (const auto& [pair, value] : rows) {
    const int i = pair.first - 1, j = pair.second - 1;  // −1 = photo 0 (fixed)
    if (i >= 0) a(i, i) += 1, b(i) += value;
    if (j >= 0) a(j, j) += 1, b(j) -= value;
    if (i >= 0 && j >= 0) a(i, j) -= 1, a(j, i) -= 1;
  }
  const Eigen::VectorXd l = a.ldlt().solve(b);
  for (int k = 0; k < n; ++k) result[k + 1] = l(k);
  return result;
}

}  // namespace

PhotosRecolorResult RecolorFromPhotos(const Scan& scan, const std::vector<CameraPhoto>& photos,
                                      const PhotosRecolorOptions& options) {
  const auto call_start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();  // process CPU time, all threads
  options.Check();
  CheckScan(scan);
  if (photos.size() > 65534) throw OptionsError("at most 65534 photos");
  for (size_t i = 0; i < photos.size(); ++i) {
    const std::string what = fmt::format("photo {}", i);
    photos[i].camera.Check(what);
    const cv::Mat& image = photos[i].image;
    if (image.type() != CV_8UC3 || image.cols != photos[i].camera.width_px() ||
        image.rows != photos[i].camera.height_px())
      ThrowInputError(
          what, "", "image",
          fmt::format("expected an 8-bit RGB image of {} x {} pixels, got {} x {}",
                      photos[i].camera.width_px(), photos[i].camera.height_px(), image.cols, image.rows));
  }
  const auto start = std::chrono::steady_clock::now();
  const auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  const recolor_internal::OcclusionScene scene =
      recolor_internal::BuildOcclusionScene(scan, options.visibility);
  const double scene_seconds = since(start);
  const int64_t cells = static_cast<int64_t>(scan.rows) * scan.cols;
  const Eigen::Matrix3d rotation = scan.world_from_scanner.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = scan.world_from_scanner.topRightCorner<3, 1>();
  const bool has_normals = !scan.normal.empty();

  // Per photo, what it sees: each cell's sample and score, in row-major cell order (computed in parallel).
  struct PhotoSample {
    int64_t cell;
    cv::Vec3b rgb;
    float score;
  };
  std::vector<std::vector<PhotoSample>> seen_by(photos.size());
  PhotosRecolorResult result;
  result.scene_seconds = scene_seconds;
  const auto visibility_start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < photos.size(); ++i) {
    const Camera& camera = photos[i].camera;
    const Eigen::Vector3d center = camera.center_in_world();
    const recolor_internal::Visibility visibility =
        recolor_internal::VisibleCells(scan, scene, camera, options.visibility, /*by_row=*/true);
    result.returns = visibility.returns;
    result.zbuffer_seconds += visibility.zbuffer_seconds;
    // Row by row into one list: each row's place is the sum of the rows before it.
    std::vector<size_t> row_start(scan.rows + 1, 0);
    for (int r = 0; r < scan.rows; ++r) row_start[r + 1] = row_start[r] + visibility.row_seen[r].size();
    std::vector<PhotoSample>& list = seen_by[i];
    list.resize(row_start[scan.rows]);
    ParallelFor(scan.rows, [&](int64_t row) {
      for (size_t j = 0; j < visibility.row_seen[row].size(); ++j) {
        const size_t k = row_start[row] + j;
        {
          const recolor_internal::SeenCell& seen = visibility.row_seen[row][j];
          const int r = static_cast<int>(seen.cell / scan.cols), c = static_cast<int>(seen.cell % scan.cols);
          double cos_angle = 1;
          if (has_normals) {
            const cv::Vec3f n = scan.normal.at<cv::Vec3f>(r, c);
            const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
            const Eigen::Vector3d normal = rotation * Eigen::Vector3d(n[0], n[1], n[2]);
            const Eigen::Vector3d view =
                (center - (rotation * Eigen::Vector3d(p[0], p[1], p[2]) + translation)).normalized();
            if (normal.norm() > 0.5) cos_angle = std::max(0.05, std::abs(normal.normalized().dot(view)));
          }
          const double border = std::min({seen.pixel.x(), seen.pixel.y(), camera.width_px() - seen.pixel.x(),
                                          camera.height_px() - seen.pixel.y()});
          const double border_factor =
              options.border_px > 0 ? std::min(1.0, (border + 0.5) / options.border_px) : 1;
          const double score = options.nearest_photo
                                   ? 1 / std::max(seen.distance_m, 1e-3)
                                   : cos_angle * border_factor / std::max(seen.distance_m, 1e-3);
          list[k] = {seen.cell, SamplePhoto(photos[i].image, seen.pixel), static_cast<float>(score)};
        }
      }
    });
  }
  result.visibility_seconds = since(visibility_start);
  result.projection_seconds = result.visibility_seconds - result.zbuffer_seconds;
  const auto choice_start = std::chrono::steady_clock::now();
  // Per cell its samples, by photo index (compressed rows: `first[cell]` .. `first[cell + 1]`), and the best
  // photo (the highest score; a tie keeps the lower index). Built over blocks of rows in parallel: each photo's
  // list is in cell order, so a block's part of it is found by binary search, and within a cell the photos
  // are visited in index order as a serial pass would (the same result on any thread count).
  const int64_t block_cells = 64 * static_cast<int64_t>(scan.cols);
  const int64_t blocks = (cells + block_cells - 1) / block_cells;
  std::vector<std::vector<size_t>> bounds(seen_by.size(), std::vector<size_t>(blocks + 1));
  for (size_t i = 0; i < seen_by.size(); ++i) {
    for (int64_t b = 0; b <= blocks; ++b) {
      bounds[i][b] = static_cast<size_t>(
          std::lower_bound(seen_by[i].begin(), seen_by[i].end(), std::min(cells, b * block_cells),
                           [](const PhotoSample& s, int64_t cell) { return s.cell < cell; }) -
          seen_by[i].begin());
    }
  }
  std::vector<int64_t> first(cells + 1, 0);
  ParallelFor(blocks, [&](int64_t b) {  // block b writes first[c + 1] for its own cells c only
    for (size_t i = 0; i < seen_by.size(); ++i) {
      for (size_t k = bounds[i][b]; k < bounds[i][b + 1]; ++k) ++first[seen_by[i][k].cell + 1];
    }
  });
  for (int64_t cell = 0; cell < cells; ++cell) first[cell + 1] += first[cell];
  std::vector<Sample> samples(static_cast<size_t>(first[cells]));
  std::vector<int> best(cells, -1);
  ParallelFor(blocks, [&](int64_t b) {
    const int64_t begin = b * block_cells, end = std::min(cells, begin + block_cells);
    std::vector<int64_t> next(first.begin() + begin, first.begin() + end);
    std::vector<float> best_score(end - begin, -1);
    for (size_t i = 0; i < seen_by.size(); ++i) {
      for (size_t k = bounds[i][b]; k < bounds[i][b + 1]; ++k) {
        const PhotoSample& s = seen_by[i][k];
        const int64_t at = s.cell - begin;
        samples[next[at]++] = {static_cast<int>(i), s.rgb};
        if (s.score > best_score[at]) best_score[at] = s.score, best[s.cell] = static_cast<int>(i);
      }
    }
  });
  std::vector<std::vector<PhotoSample>>().swap(seen_by);
  const auto samples_of = [&](int64_t cell) {
    return std::pair<const Sample*, const Sample*>(samples.data() + first[cell],
                                                   samples.data() + first[cell + 1]);
  };

  result.choice_seconds = since(choice_start);
  const auto gain_start = std::chrono::steady_clock::now();
  // The gains, channel by channel, from the overlaps and from neighbours coloured by different photos.
  // Blocks of rows in parallel, each into its own rows, joined in block order: the rows in cell order as a serial
  // pass would give them (the same sums on any thread count).
  using GainRow = std::pair<std::pair<int, int>, double>;
  struct BlockRows {
    std::vector<GainRow> rows[3];
    int64_t constraints = 0;
  };
  std::vector<BlockRows> block_rows(blocks);
  const auto sample_of = [&](int64_t cell, int photo) -> const Sample* {
    for (auto [s, end] = samples_of(cell); s != end; ++s) {
      if (s->photo == photo) return s;
    }
    return nullptr;
  };
  const auto chosen = [&](int64_t cell) { return best[cell] < 0 ? nullptr : sample_of(cell, best[cell]); };
  ParallelFor(blocks, [&](int64_t block) {
    BlockRows& out = block_rows[block];
    const auto add = [&](const Sample& a, const Sample& b) {
      if (a.photo == b.photo) return;
      for (int ch = 0; ch < 3; ++ch) {
        const double u = a.rgb[ch], v = b.rgb[ch];
        if (u < kDarkest || v < kDarkest || u > kBrightest || v > kBrightest) continue;
        out.rows[ch].push_back({{a.photo, b.photo}, std::log(u) - std::log(v)});
      }
      ++out.constraints;
    };
    const int64_t block_end = std::min(cells, (block + 1) * block_cells);
    for (int64_t cell = block * block_cells; cell < block_end; ++cell) {
      const auto [begin, end] = samples_of(cell);
      for (const Sample* a = begin; a != end; ++a) {
        for (const Sample* b = a + 1; b != end; ++b) add(*a, *b);
      }
      const int r = static_cast<int>(cell / scan.cols), c = static_cast<int>(cell % scan.cols);
      const Sample* mine = chosen(cell);
      if (mine == nullptr) continue;
      for (const int64_t other :
           {c + 1 < scan.cols ? cell + 1 : -1, r + 1 < scan.rows ? cell + scan.cols : -1}) {
        if (other < 0 || best[other] < 0 || best[other] == best[cell]) continue;
        add(*mine, *chosen(other));
      }
    }
  });
  std::vector<GainRow> rows[3];
  for (BlockRows& block : block_rows) {
    for (int ch = 0; ch < 3; ++ch)
      rows[ch].insert(rows[ch].end(), block.rows[ch].begin(), block.rows[ch].end());
    result.constraints += block.constraints;
  }
  result.gains.assign(photos.size(), cv::Vec3d(1, 1, 1));
  if (options.equalize_exposure) {
    for (int ch = 0; ch < 3; ++ch) {
      const std::vector<double> log_gains = FitLogGains(static_cast<int>(photos.size()), rows[ch]);
      for (size_t i = 0; i < photos.size(); ++i) result.gains[i][ch] = std::exp(log_gains[i]);
    }
  }

  result.gain_seconds = since(gain_start);
  const auto colour_start = std::chrono::steady_clock::now();
  // The chosen colours at photo 0's exposure (as float: the blend's values, rounded once on output), then the
  // seams blended. No grid of colours: a cell's colour is its chosen sample's, read where needed.
  const auto corrected = [&](const Sample& sample) {
    const cv::Vec3d& gain = result.gains[sample.photo];
    return cv::Vec3d(sample.rgb[0] / gain[0], sample.rgb[1] / gain[1], sample.rgb[2] / gain[2]);
  };
  const auto colour_of = [&](int64_t cell) {
    const cv::Vec3d v = corrected(*chosen(cell));
    // Through memory: the colours must be floats (the guidance is the difference of two of them, as when a
    // grid of float colours held them), and GCC 12 at -O2 was seen to use the unrounded doubles instead.
    volatile float rounded[3] = {static_cast<float>(v[0]), static_cast<float>(v[1]),
                                 static_cast<float>(v[2])};
    return cv::Vec3f(rounded[0], rounded[1], rounded[2]);
  };
  result.photo_index = cv::Mat(scan.rows, scan.cols, CV_16U);
  std::vector<int64_t> row_coloured(scan.rows, 0);
  ParallelFor(scan.rows, [&](int64_t row) {
    const int r = static_cast<int>(row);
    uint16_t* index_row = result.photo_index.ptr<uint16_t>(r);
    const int* best_row = best.data() + row * scan.cols;
    for (int c = 0; c < scan.cols; ++c) {
      index_row[c] = static_cast<uint16_t>(best_row[c] + 1);
      row_coloured[r] += best_row[c] >= 0;
    }
  });
  for (const int64_t n : row_coloured) result.coloured += n;
  result.colour_seconds = since(colour_start);
  SeamBandSolution band;
  if (options.blend_seams) {
    const auto blend_start = std::chrono::steady_clock::now();
    const cv::Mat& range = scan.range;
    // The guidance from cell a to its neighbour b: their own difference when one photo colours both, else
    // what the photos that see both show, else 0 on a continuous surface and the step across a depth jump.
    const auto guidance = [&](int64_t a, int64_t b) -> cv::Vec3d {
      const cv::Vec3f fa = colour_of(a), fb = colour_of(b);
      const cv::Vec3d ua(fa[0], fa[1], fa[2]), ub(fb[0], fb[1], fb[2]);
      if (best[a] == best[b]) return ub - ua;
      cv::Vec3d sum(0, 0, 0);
      int count = 0;
      for (const int photo : {best[a], best[b]}) {
        const Sample *sa = sample_of(a, photo), *sb = sample_of(b, photo);
        if (sa == nullptr || sb == nullptr) continue;
        sum += corrected(*sb) - corrected(*sa);
        ++count;
      }
      if (count > 0) return sum / count;
      const double da = range.at<float>(static_cast<int>(a / scan.cols), static_cast<int>(a % scan.cols));
      const double db = range.at<float>(static_cast<int>(b / scan.cols), static_cast<int>(b % scan.cols));
      if (std::abs(da - db) > options.seam_depth_jump_m + 0.02 * std::min(da, db)) return ub - ua;
      return cv::Vec3d(0, 0, 0);
    };
    band = SolveSeamBand(result.photo_index, options.seam_band_cells, colour_of,
                         [&](int64_t cell, bool down) -> cv::Vec3f {
                           return guidance(cell, down ? cell + scan.cols : cell + 1);
                         });
    result.seam_edges = band.seam_edges;
    result.blended = static_cast<int64_t>(band.cells.size());
    result.blend_seconds = since(blend_start);
  }

  const auto output_start = std::chrono::steady_clock::now();
  result.scan = Clone(scan);
  Scan& out = result.scan;
  if (!out.has_color()) out.color = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));
  const auto write = [&](int64_t cell, const cv::Vec3f& v) {
    out.color.at<cv::Vec3b>(static_cast<int>(cell / scan.cols), static_cast<int>(cell % scan.cols)) =
        cv::Vec3b(cv::saturate_cast<uint8_t>(static_cast<double>(v[0])),
                  cv::saturate_cast<uint8_t>(static_cast<double>(v[1])),
                  cv::saturate_cast<uint8_t>(static_cast<double>(v[2])));
  };
  ParallelFor(scan.rows, [&](int64_t row) {
    for (int64_t cell = row * scan.cols; cell < (row + 1) * scan.cols; ++cell) {
      if (best[cell] >= 0) write(cell, colour_of(cell));
    }
  });
  ParallelForRange(static_cast<int64_t>(band.cells.size()), [&](int64_t begin, int64_t end) {
    for (int64_t k = begin; k < end; ++k) write(band.cells[k], band.colour[k]);
  });
  result.output_seconds = since(output_start);
  result.total_seconds = since(call_start);
  result.cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  return result;
}

E57StationPhotos StationPhotosOfE57(const E57File& file, int scan_index) {
  E57StationPhotos result;
  for (size_t i = 0; i < file.images.size(); ++i) {
    const E57Image& image = file.images[i];
    Camera camera;
    std::string why;
    if (image.associated_scan >= 0 && image.associated_scan != scan_index) {
      why = fmt::format("belongs to scan {}", image.associated_scan);
    } else if (image.image.empty()) {
      why = image.decode_error;
    } else if (CameraModelOfE57Image(image, &camera, &why)) {
      result.photos.push_back({image.image, camera});
      result.image_index.push_back(static_cast<int>(i));
      continue;
    }
    result.skipped.push_back({static_cast<int>(i), why});
  }
  return result;
}

}  // namespace lidarshop
