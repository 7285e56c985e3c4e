#include "lidarshop/inpaint/offset_completion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <maxflow/graph.h>
#include <nanoflann.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

void OffsetCompletionOptions::Check() const { Validate(*this); }

namespace {

// Cost of a seam against a pixel that cannot be copied (outside the image or in the hole): above any real
// difference of grey-level channels, so that a labelling avoids it wherever it can.
constexpr double kUncopyable = 1e7;

// The image with every channel scaled by √weight, so that squared differences are the weighted ones.
struct Weighted {
  int rows = 0, cols = 0, channels = 0;
  std::vector<float> values;
  cv::Mat hole;  // CV_8U, non-zero = hole
  bool Known(int r, int c) const {
    return r >= 0 && r < rows && c >= 0 && c < cols && hole.at<uint8_t>(r, c) == 0;
  }
  const float* At(int r, int c) const { return values.data() + (int64_t{r} * cols + c) * channels; }
  double Difference(int r0, int c0, int r1, int c1) const {
    const float* a = At(r0, c0);
    const float* b = At(r1, c1);
    double sum = 0;
    for (int k = 0; k < channels; ++k) {
      const double d = double{a[k]} - double{b[k]};
      sum += d * d;
    }
    return sum;
  }
};

Weighted MakeWeighted(const cv::Mat& image, const cv::Mat& hole, const std::vector<float>& weights) {
  Weighted w;
  w.rows = image.rows;
  w.cols = image.cols;
  w.channels = image.channels();
  w.hole = hole != 0;
  w.values.resize(static_cast<size_t>(int64_t{w.rows} * w.cols * w.channels));
  std::vector<float> root(w.channels, 1.0f);
  for (int k = 0; k < w.channels && !weights.empty(); ++k) root[k] = std::sqrt(weights[k]);
  for (int r = 0; r < w.rows; ++r) {
    const float* in = image.ptr<float>(r);
    float* out = w.values.data() + int64_t{r} * w.cols * w.channels;
    for (int c = 0; c < w.cols; ++c) {
      const bool known = w.hole.at<uint8_t>(r, c) == 0;
      for (int k = 0; k < w.channels; ++k) {
        const float v = in[c * w.channels + k];
        if (known && !std::isfinite(v)) {
          ThrowInputError("", fmt::format("pixel (row {}, col {})", r, c), "image",
                          fmt::format("channel {} is not finite outside the hole", k));
        }
        out[c * w.channels + k] = known ? v * root[k] : 0.0f;
      }
    }
  }
  return w;
}

// Row-major descriptors for nanoflann.
struct Descriptors {
  cv::Mat rows;  // CV_32F N x dims
  size_t kdtree_get_point_count() const { return static_cast<size_t>(rows.rows); }
  float kdtree_get_pt(size_t index, size_t dim) const {
    return rows.at<float>(static_cast<int>(index), static_cast<int>(dim));
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using DescriptorTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Descriptors, float, uint32_t>,
                                        Descriptors, -1, uint32_t>;

// The dominant offsets with their smoothed votes (step 1 of the header), most votes first.
void DominantOffsets(const Weighted& im, const OffsetCompletionOptions& options,
                     std::vector<cv::Point>* offsets, std::vector<float>* votes) {
  const int R = options.patch_radius, side = 2 * R + 1;
  // Patch centres with the whole patch known, on a grid coarse enough for max_samples.
  cv::Mat hole01 = im.hole / 255, integral;
  cv::integral(hole01, integral, CV_32S);
  auto whole_patch_known = [&](int r, int c) {
    if (r < R || c < R || r + R >= im.rows || c + R >= im.cols) return false;
    return integral.at<int>(r + R + 1, c + R + 1) - integral.at<int>(r - R, c + R + 1) -
               integral.at<int>(r + R + 1, c - R) + integral.at<int>(r - R, c - R) ==
           0;
  };
  int step = options.sample_step;
  std::vector<cv::Point> centres;
  for (;; ++step) {
    centres.clear();
    for (int r = R; r + R < im.rows; r += step)
      for (int c = R; c + R < im.cols; c += step)
        if (whole_patch_known(r, c)) centres.push_back({c, r});
    if (static_cast<int>(centres.size()) <= options.max_samples) break;
  }
  if (centres.size() < 2) return;
  const int raw_dims = side * side * im.channels;
  cv::Mat raw(static_cast<int>(centres.size()), raw_dims, CV_32F);
  for (int i = 0; i < raw.rows; ++i) {
    float* out = raw.ptr<float>(i);
    for (int dr = -R; dr <= R; ++dr) {
      const float* row = im.At(centres[i].y + dr, centres[i].x - R);
      std::copy(row, row + side * im.channels, out + (dr + R) * side * im.channels);
    }
  }
  const int dims = std::min(options.descriptor_dims, raw_dims);
  // Principal components from an evenly spaced subsample (at most 1500 patches), applied to all: the covariance
  // of 9 x 9 x 6 values costs samples x 486² (measured: 0.37 s for 4,000 patches, 0.16 s for 1,500, and the
  // same fills of data/fill_eval).
  const int every = std::max(1, raw.rows / 1500);
  cv::Mat sample;
  for (int i = 0; i < raw.rows; i += every) sample.push_back(raw.row(i));
  const cv::PCA pca(sample, cv::noArray(), cv::PCA::DATA_AS_ROW, dims);
  Descriptors descriptors{pca.project(raw)};
  const DescriptorTree tree(descriptors.rows.cols, descriptors,
                            nanoflann::KDTreeSingleIndexAdaptorParams(16));

  // Each patch's nearest neighbour at least min_offset away votes for the offset to it.
  constexpr int kNeighbours = 8;
  std::vector<cv::Point> nearest(centres.size(), cv::Point(0, 0));
  ParallelFor(static_cast<int64_t>(centres.size()), [&](int64_t i) {
    std::array<uint32_t, kNeighbours> index{};
    std::array<float, kNeighbours> distance{};
    nanoflann::KNNResultSet<float, uint32_t> result(kNeighbours);
    result.init(index.data(), distance.data());
    tree.findNeighbors(result, descriptors.rows.ptr<float>(static_cast<int>(i)), nanoflann::SearchParams());
    for (size_t k = 0; k < result.size(); ++k) {
      const cv::Point offset = centres[index[k]] - centres[static_cast<size_t>(i)];
      if (std::max(std::abs(offset.x), std::abs(offset.y)) >= options.min_offset) {
        nearest[static_cast<size_t>(i)] = offset;
        break;
      }
    }
  });
  cv::Mat histogram = cv::Mat::zeros(2 * im.rows - 1, 2 * im.cols - 1, CV_32F);
  for (const cv::Point& o : nearest)
    if (o != cv::Point(0, 0)) histogram.at<float>(o.y + im.rows - 1, o.x + im.cols - 1) += 1.0f;
  cv::GaussianBlur(histogram, histogram, cv::Size(0, 0), std::sqrt(2.0));
  cv::Mat local_max;
  cv::dilate(histogram, local_max, cv::Mat());
  struct Peak {
    float votes;
    cv::Point offset;
  };
  std::vector<Peak> peaks;
  for (int y = 0; y < histogram.rows; ++y)
    for (int x = 0; x < histogram.cols; ++x) {
      const float v = histogram.at<float>(y, x);
      const cv::Point o(x - (im.cols - 1), y - (im.rows - 1));
      if (v > 1e-3f && v >= local_max.at<float>(y, x) &&
          std::max(std::abs(o.x), std::abs(o.y)) >= options.min_offset)
        peaks.push_back({v, o});
    }
  std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) {
    if (a.votes != b.votes) return a.votes > b.votes;
    return a.offset.y != b.offset.y ? a.offset.y < b.offset.y : a.offset.x < b.offset.x;
  });

  // Refine each peak to the shift (within one pixel) whose copy differs least from the image, over a grid of
  // known pixels; the grid of patch centres only votes for multiples of its step.
  // About 60 000 pixels, whatever the image's size.
  const int refine_step =
      std::max(1, static_cast<int>(std::sqrt(static_cast<double>(im.rows) * im.cols / 60000.0)));
  auto mean_difference = [&](cv::Point o) {
    double sum = 0;
    int64_t count = 0;
    for (int r = 0; r < im.rows; r += refine_step)
      for (int c = 0; c < im.cols; c += refine_step) {
        if (!im.Known(r, c) || !im.Known(r + o.y, c + o.x)) continue;
        sum += im.Difference(r, c, r + o.y, c + o.x);
        ++count;
      }
    return count > 0 ? sum / static_cast<double>(count) : std::numeric_limits<double>::infinity();
  };
  const size_t wanted = std::min(peaks.size(), static_cast<size_t>(options.labels));
  std::vector<cv::Point> refined(wanted);
  ParallelFor(static_cast<int64_t>(wanted), [&](int64_t i) {
    const cv::Point o = peaks[static_cast<size_t>(i)].offset;
    cv::Point best = o;
    double best_difference = std::numeric_limits<double>::infinity();
    const int reach = step > 1 ? 1 : 0;
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        const cv::Point candidate = o + cv::Point(dx, dy);
        if (std::max(std::abs(candidate.x), std::abs(candidate.y)) < options.min_offset) continue;
        const double d = mean_difference(candidate);
        if (d < best_difference) best_difference = d, best = candidate;
      }
    refined[static_cast<size_t>(i)] = best;
  });
  for (size_t i = 0; i < wanted; ++i) {
    if (std::find(offsets->begin(), offsets->end(), refined[i]) != offsets->end()) continue;
    offsets->push_back(refined[i]);
    votes->push_back(peaks[i].votes);
  }
}

// The labelling and its energy (steps 2 and 3 of the header).
class Labelling {
 public:
  Labelling(const Weighted& im, const std::vector<cv::Point>& offsets) : im_(im), offsets_(offsets) {
    node_of_pixel_.assign(static_cast<size_t>(int64_t{im.rows} * im.cols), -1);
    for (int r = 0; r < im.rows; ++r)
      for (int c = 0; c < im.cols; ++c) {
        if (im.Known(r, c)) continue;
        node_of_pixel_[Index(r, c)] = static_cast<int32_t>(pixels_.size());
        pixels_.push_back({c, r});
      }
    label_.assign(pixels_.size(), -1);
    for (size_t n = 0; n < pixels_.size(); ++n) {
      double best = std::numeric_limits<double>::infinity();
      for (int l = 0; l < static_cast<int>(offsets_.size()); ++l) {
        if (!Valid(n, l)) continue;
        const double d = Data(n, l);
        if (d < best) best = d, label_[n] = l;
      }
    }
  }

  size_t size() const { return pixels_.size(); }
  int label(size_t n) const { return label_[n]; }
  cv::Point pixel(size_t n) const { return pixels_[n]; }

  double Energy() const {
    double e = 0;
    for (size_t n = 0; n < pixels_.size(); ++n) {
      if (label_[n] < 0) continue;
      e += Data(n, label_[n]);
      for (int m : ForwardNeighbours(n))
        if (m >= 0 && label_[static_cast<size_t>(m)] >= 0)
          e += Pairwise(n, static_cast<size_t>(m), label_[n], label_[static_cast<size_t>(m)]);
    }
    return e;
  }

  // One expansion move towards `alpha`; kept when it lowers the energy. Returns whether it did.
  bool Expand(int alpha, double* energy) {
    std::vector<int32_t> node(pixels_.size(), -1);
    int nodes = 0;
    for (size_t n = 0; n < pixels_.size(); ++n)
      if (label_[n] >= 0 && label_[n] != alpha && Valid(n, alpha)) node[n] = nodes++;
    if (nodes == 0) return false;
    maxflow::Graph<double, double, double> graph(nodes, 2 * nodes);
    graph.add_node(nodes);
    std::vector<double> keep(static_cast<size_t>(nodes), 0.0), change(static_cast<size_t>(nodes), 0.0);
    for (size_t n = 0; n < pixels_.size(); ++n) {
      if (node[n] < 0) continue;
      keep[node[n]] += Data(n, label_[n]);
      change[node[n]] += Data(n, alpha);
    }
    for (size_t n = 0; n < pixels_.size(); ++n) {
      if (label_[n] < 0) continue;
      for (int m_int : ForwardNeighbours(n)) {
        if (m_int < 0) continue;
        const auto m = static_cast<size_t>(m_int);
        if (label_[m] < 0 || (node[n] < 0 && node[m] < 0)) continue;
        if (node[n] >= 0 && node[m] >= 0) {
          // E(x_n, x_m) with x = 1 for "becomes alpha": A = E(0,0), B = E(0,1), C = E(1,0), E(1,1) = 0.
          const double b = Pairwise(n, m, label_[n], alpha), c = Pairwise(n, m, alpha, label_[m]);
          const double a = std::min(Pairwise(n, m, label_[n], label_[m]), b + c);  // submodular part
          // E = A + (C − A) x_n + (0 − C) x_m + (B + C − A)(1 − x_n) x_m
          AddUnary(node[n], c - a, &keep, &change);
          AddUnary(node[m], -c, &keep, &change);
          graph.add_edge(node[n], node[m], b + c - a, 0.0);
        } else if (node[n] >= 0) {
          keep[node[n]] += Pairwise(n, m, label_[n], label_[m]);
          change[node[n]] += Pairwise(n, m, alpha, label_[m]);
        } else {
          keep[node[m]] += Pairwise(n, m, label_[n], label_[m]);
          change[node[m]] += Pairwise(n, m, label_[n], alpha);
        }
      }
    }
    for (int i = 0; i < nodes; ++i) {
      // x = 1 (alpha) is the sink side: its cost is the source edge's capacity.
      const double low = std::min(keep[i], change[i]);
      graph.add_tweights(i, change[i] - low, keep[i] - low);
    }
    graph.maxflow();
    std::vector<size_t> changed;
    for (size_t n = 0; n < pixels_.size(); ++n)
      if (node[n] >= 0 && graph.what_segment(node[n]) == maxflow::Graph<double, double, double>::SINK)
        changed.push_back(n);
    if (changed.empty()) return false;
    // The true energy change (the move was solved for the truncated one): the changed pixels' data terms and
    // every pairwise term they take part in, each pair once.
    std::vector<int> before(changed.size());
    for (size_t i = 0; i < changed.size(); ++i) before[i] = label_[changed[i]];
    double delta = 0;
    auto pairs_of_changed = [&](double sign) {
      for (size_t n : changed) {
        delta += sign * Data(n, label_[n]);
        for (int m_int : Neighbours(n)) {
          if (m_int < 0 || label_[static_cast<size_t>(m_int)] < 0) continue;
          const auto m = static_cast<size_t>(m_int);
          // A pair of two changed pixels is counted from its lower index only.
          if (node[m] >= 0 && std::binary_search(changed.begin(), changed.end(), m) && m < n) continue;
          delta += sign * Pairwise(n, m, label_[n], label_[m]);
        }
      }
    };
    pairs_of_changed(-1.0);
    for (size_t n : changed) label_[n] = alpha;
    pairs_of_changed(1.0);
    if (delta < 0) {
      *energy += delta;
      return true;
    }
    for (size_t i = 0; i < changed.size(); ++i) label_[changed[i]] = before[i];
    return false;
  }

 private:
  size_t Index(int r, int c) const { return static_cast<size_t>(int64_t{r} * im_.cols + c); }

  bool Valid(size_t n, int l) const {
    const cv::Point p = pixels_[n] + offsets_[static_cast<size_t>(l)];
    return im_.Known(p.y, p.x);
  }

  // The seam with the known 4-neighbours of the pixel.
  double Data(size_t n, int l) const {
    const cv::Point p = pixels_[n], o = offsets_[static_cast<size_t>(l)];
    double cost = 0;
    for (const cv::Point d : {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
      const cv::Point q = p + d;
      if (!im_.Known(q.y, q.x)) continue;
      const cv::Point from = q + o;
      cost += im_.Known(from.y, from.x) ? im_.Difference(q.y, q.x, from.y, from.x) : kUncopyable;
    }
    return cost;
  }

  // Disagreement of the copies by offsets a and b at one pixel.
  double Copies(cv::Point p, int a, int b) const {
    const cv::Point pa = p + offsets_[static_cast<size_t>(a)], pb = p + offsets_[static_cast<size_t>(b)];
    if (!im_.Known(pa.y, pa.x) || !im_.Known(pb.y, pb.x)) return kUncopyable;
    return im_.Difference(pa.y, pa.x, pb.y, pb.x);
  }

  double Pairwise(size_t n, size_t m, int a, int b) const {
    if (a == b) return 0.0;
    return Copies(pixels_[n], a, b) + Copies(pixels_[m], a, b);
  }

  // The hole neighbours in all four directions (−1: known or outside).
  std::array<int, 4> Neighbours(size_t n) const {
    const cv::Point p = pixels_[n];
    std::array<int, 4> out{-1, -1, -1, -1};
    if (p.x + 1 < im_.cols) out[0] = node_of_pixel_[Index(p.y, p.x + 1)];
    if (p.y + 1 < im_.rows) out[1] = node_of_pixel_[Index(p.y + 1, p.x)];
    if (p.x > 0) out[2] = node_of_pixel_[Index(p.y, p.x - 1)];
    if (p.y > 0) out[3] = node_of_pixel_[Index(p.y - 1, p.x)];
    return out;
  }

  // The hole neighbours to the right and below (each pair once).
  std::array<int, 2> ForwardNeighbours(size_t n) const {
    const cv::Point p = pixels_[n];
    std::array<int, 2> out{-1, -1};
    if (p.x + 1 < im_.cols) out[0] = node_of_pixel_[Index(p.y, p.x + 1)];
    if (p.y + 1 < im_.rows) out[1] = node_of_pixel_[Index(p.y + 1, p.x)];
    return out;
  }

  static void AddUnary(int node, double cost_of_alpha, std::vector<double>* keep,
                       std::vector<double>* change) {
    if (cost_of_alpha >= 0)
      (*change)[static_cast<size_t>(node)] += cost_of_alpha;
    else
      (*keep)[static_cast<size_t>(node)] -= cost_of_alpha;
  }

  const Weighted& im_;
  const std::vector<cv::Point>& offsets_;
  std::vector<int32_t> node_of_pixel_;  // rows*cols, −1 = known
  std::vector<cv::Point> pixels_;       // hole pixels, row-major
  std::vector<int> label_;              // per hole pixel, −1 = no valid offset
};

}  // namespace

OffsetCompletionResult CompleteByOffsets(const cv::Mat& image, const cv::Mat& hole,
                                         const OffsetCompletionOptions& options) {
  options.Check();
  Timer timer;
  if (image.empty() || image.depth() != CV_32F || image.channels() > 16)
    ThrowInputError("", "", "image", "expected a float image with 1..16 channels");
  if (hole.type() != CV_8UC1 || hole.size() != image.size()) {
    ThrowInputError("", "", "mask",
                    fmt::format("expected an 8-bit mask of the image's size {}x{}", image.cols, image.rows));
  }
  if (!options.channel_weights.empty() &&
      static_cast<int>(options.channel_weights.size()) != image.channels()) {
    throw OptionsError(fmt::format("OffsetCompletionOptions: {} channel weights for an image of {} channels",
                                   options.channel_weights.size(), image.channels()));
  }
  const Weighted im = MakeWeighted(image, hole, options.channel_weights);
  OffsetCompletionResult result;
  result.label = cv::Mat(image.size(), CV_32S, cv::Scalar(-1));
  result.source_pixel = cv::Mat(image.size(), CV_32SC2, cv::Scalar(-1, -1));
  DominantOffsets(im, options, &result.offsets, &result.votes);

  Labelling labelling(im, result.offsets);
  double energy = labelling.Energy();
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    int moved = 0;
    for (int alpha = 0; alpha < static_cast<int>(result.offsets.size()); ++alpha)
      moved += labelling.Expand(alpha, &energy) ? 1 : 0;
    result.moves += moved;
    if (moved == 0) break;
  }
  for (size_t n = 0; n < labelling.size(); ++n) {
    const cv::Point p = labelling.pixel(n);
    const int l = labelling.label(n);
    if (l < 0) {
      ++result.unfilled;
      continue;
    }
    const cv::Point from = p + result.offsets[static_cast<size_t>(l)];
    result.label.at<int32_t>(p.y, p.x) = l;
    result.source_pixel.at<cv::Vec2i>(p.y, p.x) = cv::Vec2i(from.y, from.x);
  }
  result.energy = energy;
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace lidarshop
