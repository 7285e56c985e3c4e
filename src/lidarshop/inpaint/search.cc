#include "lidarshop/inpaint/search.h"

#include <algorithm>
#include <mutex>
#include <unordered_set>

#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

namespace {

// Keeps the k best candidates seen (by CandidateBefore); Bound() is the k-th best
// difference (infinity until k).
class TopK {
 public:
  explicit TopK(int k) : k_(k) { best_.reserve(k + 1); }
  float Bound() const {
    return static_cast<int>(best_.size()) < k_ ? std::numeric_limits<float>::infinity()
                                               : best_.back().difference;
  }
  void Offer(const SourceCandidate& candidate) {
    if (static_cast<int>(best_.size()) == k_ && !CandidateBefore(candidate, best_.back())) return;
    auto it = std::upper_bound(best_.begin(), best_.end(), candidate, CandidateBefore);
    best_.insert(it, candidate);
    if (static_cast<int>(best_.size()) > k_) best_.pop_back();
  }
  const std::vector<SourceCandidate>& best() const { return best_; }

 private:
  int k_;
  std::vector<SourceCandidate> best_;
};

uint64_t NextSplitMix64(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// The i-th row of [row_begin, row_end) counted from its middle outwards (middle, middle + 1, middle − 1,
// middle + 2, ...; then the rest of the longer side): windows are centred on the target, and nearby sources
// are the likeliest good ones, so scanning them first tightens the early-termination bound sooner.
int RowFromMiddle(int row_begin, int row_end, int i) {
  const int middle = row_begin + (row_end - row_begin) / 2;
  const int below = row_end - middle - 1, above = middle - row_begin;  // rows after / before the middle
  const int paired = std::min(below, above);
  if (i <= 2 * paired) return i % 2 == 1 ? middle + (i + 1) / 2 : middle - i / 2;
  const int rest = i - 2 * paired;  // beyond the shorter side: continue on the longer one
  return below > above ? middle + paired + rest : middle - paired - rest;
}

int UniformInt(uint64_t& state, int n) {
  return static_cast<int>((NextSplitMix64(state) >> 11) % static_cast<uint64_t>(n));
}

}  // namespace

bool CandidateBefore(const SourceCandidate& a, const SourceCandidate& b) {
  if (a.difference != b.difference) return a.difference < b.difference;
  if (a.source.row != b.source.row) return a.source.row < b.source.row;
  return a.source.col < b.source.col;
}

std::vector<SourceCandidate> ExhaustiveSearch::FindBelow(const InpaintCanvas& canvas,
                                                         const TargetDifference& difference, Pixel target,
                                                         int count, float bound, int row_begin, int row_end,
                                                         int col_begin, int col_end) {
  const auto& cols_by_row = canvas.source_cols_by_row();
  const cv::Rect fits = canvas.SourceBox(target);
  row_begin = std::max(row_begin, fits.y);
  row_end = std::min(row_end, fits.y + fits.height);
  col_begin = std::max(col_begin, fits.x);
  col_end = std::min(col_end, fits.x + fits.width);
  if (row_end <= row_begin) return {};
  std::mutex merge_mutex;
  TopK merged(count);
  // The least count-th best difference of any chunk so far. Every chunk's count-th best is >= the count-th
  // best of the whole range (a chunk is a subset of it), so no candidate of the answer is ever above this
  // bound: sharing it between the chunks (and threads) keeps the answer exact while the scan of each chunk
  // prunes against the best bound found anywhere, as one sequential scan would. Only how early a rejected
  // candidate stops depends on the timing, never which candidates are kept.
  std::atomic<float> shared_bound{bound};
  auto tighten = [&](float chunk_bound) {
    float now = shared_bound.load(std::memory_order_relaxed);
    while (chunk_bound < now &&
           !shared_bound.compare_exchange_weak(now, chunk_bound, std::memory_order_relaxed)) {
    }
  };
  ParallelForRange(
      row_end - row_begin,
      [&](int64_t begin, int64_t end) {
        TopK local(count);
        int64_t evaluated = 0;
        for (int64_t i = begin; i < end; ++i) {
          const int r = RowFromMiddle(row_begin, row_end, static_cast<int>(i));
          const std::vector<int>& cols = cols_by_row[r];
          auto first = std::lower_bound(cols.begin(), cols.end(), col_begin);
          auto last = std::lower_bound(first, cols.end(), col_end);
          // Runs of up to kRun adjacent columns are evaluated together (they share the target's loads). The
          // run is evaluated against the bound at its start; each result is re-checked against the bound at
          // its turn, so the kept candidates are exactly those a one-by-one scan keeps.
          constexpr int kRun = 4;
          float d[kRun];
          for (auto it = first; it != last;) {
            int run = 1;
            while (run < kRun && it + run != last && *(it + run) == *it + run) ++run;
            difference.EvaluateRun({r, *it}, run,
                                   std::min(shared_bound.load(std::memory_order_relaxed), local.Bound()), d);
            for (int k = 0; k < run; ++k) {
              if (d[k] > std::min(shared_bound.load(std::memory_order_relaxed), local.Bound())) continue;
              local.Offer({{r, *it + k}, d[k]});
              tighten(local.Bound());
            }
            evaluated += run;
            it += run;
          }
        }
        evaluations_ += evaluated;
        std::lock_guard<std::mutex> lock(merge_mutex);
        for (const SourceCandidate& c : local.best()) merged.Offer(c);
      },
      4);
  return merged.best();
}

void MergeCandidates(std::vector<SourceCandidate>& all, int count) {
  std::sort(all.begin(), all.end(), CandidateBefore);
  all.erase(
      std::unique(all.begin(), all.end(),
                  [](const SourceCandidate& a, const SourceCandidate& b) { return a.source == b.source; }),
      all.end());
  if (static_cast<int>(all.size()) > count) all.resize(count);
}

std::vector<SourceCandidate> ExhaustiveSearch::FindNear(const InpaintCanvas& canvas,
                                                        const TargetDifference& difference, Pixel target,
                                                        int count, int radius) {
  // Nearby sources are often good, so a small window first gives the scan of the whole image a tight early-
  // termination bound from its first candidate on. Exact: the scan keeps every candidate <= that bound.
  const float inf = std::numeric_limits<float>::infinity();
  const int w = 2 * canvas.patch_radius() + 1;
  auto nearby = FindBelow(canvas, difference, target, count, inf, target.row - w, target.row + w + 1,
                          target.col - w, target.col + w + 1);
  const float bound = static_cast<int>(nearby.size()) == count ? nearby.back().difference : inf;
  auto all = FindBelow(canvas, difference, target, count, bound, target.row - radius, target.row + radius + 1,
                       target.col - radius, target.col + radius + 1);
  // Merge (the scan re-finds the nearby ones that are good enough; keep each source once).
  all.insert(all.end(), nearby.begin(), nearby.end());
  MergeCandidates(all, count);
  return all;
}

std::vector<SourceCandidate> ExhaustiveSearch::Find(const InpaintCanvas& canvas,
                                                    const TargetDifference& difference, Pixel target,
                                                    int count) {
  return FindNear(canvas, difference, target, count, std::max(canvas.rows(), canvas.cols()));
}

std::vector<SourceCandidate> LocalSearch::Find(const InpaintCanvas& canvas,
                                               const TargetDifference& difference, Pixel target, int count) {
  const int w = window_radius_;
  auto result =
      exhaustive_.FindBelow(canvas, difference, target, count, std::numeric_limits<float>::infinity(),
                            target.row - w, target.row + w + 1, target.col - w, target.col + w + 1);
  if (result.empty()) result = exhaustive_.Find(canvas, difference, target, count);
  evaluations_ = exhaustive_.evaluations();
  return result;
}

std::vector<SourceCandidate> TwoStepSearch::Find(const InpaintCanvas& canvas,
                                                 const TargetDifference& difference, Pixel target,
                                                 int count) {
  const int w = window_radius_;
  const float inf = std::numeric_limits<float>::infinity();
  auto local = exhaustive_.FindBelow(canvas, difference, target, count, inf, target.row - w,
                                     target.row + w + 1, target.col - w, target.col + w + 1);
  const float local_bound = static_cast<int>(local.size()) == count ? local.back().difference : inf;
  // A global candidate must satisfy difference·gain <= local bound to enter the merged top-k.
  auto global =
      exhaustive_.FindBelow(canvas, difference, target, count, static_cast<float>(local_bound / global_gain_),
                            0, canvas.rows(), 0, canvas.cols());
  evaluations_ = exhaustive_.evaluations();
  // Rank: local candidates by their difference, global ones (not inside the window) by difference·gain.
  auto in_window = [&](Pixel p) {
    return std::abs(p.row - target.row) <= w && std::abs(p.col - target.col) <= w;
  };
  std::vector<std::pair<SourceCandidate, SourceCandidate>> ranked;  // (ranking key, true candidate)
  for (const auto& c : local) ranked.push_back({c, c});
  for (const auto& c : global) {
    if (in_window(c.source)) continue;
    ranked.push_back({{c.source, static_cast<float>(c.difference * global_gain_)}, c});
  }
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& a, const auto& b) { return CandidateBefore(a.first, b.first); });
  std::vector<SourceCandidate> result;
  for (size_t i = 0; i < ranked.size() && static_cast<int>(i) < count; ++i)
    result.push_back(ranked[i].second);
  return result;
}

void PatchMatchOptions::Check() const {
  CheckOption(random_samples >= 1,
              fmt::format("PatchMatchOptions.random_samples must be >= 1, got {}", random_samples));
  CheckOption(local_samples >= 0,
              fmt::format("PatchMatchOptions.local_samples must be >= 0, got {}", local_samples));
  CheckOption(local_radius >= 1,
              fmt::format("PatchMatchOptions.local_radius must be >= 1, got {}", local_radius));
  CheckOption(iterations >= 0, fmt::format("PatchMatchOptions.iterations must be >= 0, got {}", iterations));
  CheckOption(alpha > 0.0 && alpha < 1.0,
              fmt::format("PatchMatchOptions.alpha must be in (0, 1), got {}", alpha));
}

PatchMatchSearch::PatchMatchSearch(PatchMatchOptions options) : options_(options) { options_.Check(); }

std::vector<SourceCandidate> PatchMatchSearch::Find(const InpaintCanvas& canvas,
                                                    const TargetDifference& difference, Pixel target,
                                                    int count) {
  const auto& sources = canvas.source_centers();
  if (sources.empty()) return {};
  uint64_t rng =
      options_.seed * 0x9e3779b97f4a7c15ull + static_cast<uint64_t>(canvas.Index(target.row, target.col));
  TopK top(count);
  std::unordered_set<int64_t> seen;
  int64_t evaluated = 0;
  auto offer = [&](int r, int c) {
    if (!canvas.Inside(r, c) || !canvas.IsSource(r, c) || !canvas.SourceFits(target, {r, c})) return;
    if (!seen.insert(canvas.Index(r, c)).second) return;
    const float bound = top.Bound();
    const float d = difference.Evaluate({r, c}, bound);
    ++evaluated;
    if (d <= bound) top.Offer({{r, c}, d});
  };
  // Propagation from filled pixels in and around the target patch.
  const int R = canvas.patch_radius(), reach = R + 1;
  const cv::Mat& source_pixel = canvas.source_pixel();
  for (int r = target.row - reach; r <= target.row + reach; ++r) {
    for (int c = target.col - reach; c <= target.col + reach; ++c) {
      if (!canvas.Inside(r, c)) continue;
      const cv::Vec2i s = source_pixel.at<cv::Vec2i>(r, c);
      if (s[0] < 0) continue;
      offer(s[0] - (r - target.row), s[1] - (c - target.col));
    }
  }
  for (const cv::Point& offset : recent_offsets_) offer(target.row + offset.y, target.col + offset.x);
  for (int i = 0; i < options_.random_samples; ++i) {
    const Pixel& s = sources[UniformInt(rng, static_cast<int>(sources.size()))];
    offer(s.row, s.col);
  }
  for (int i = 0; i < options_.local_samples; ++i) {
    const int w = options_.local_radius;
    offer(target.row + UniformInt(rng, 2 * w + 1) - w, target.col + UniformInt(rng, 2 * w + 1) - w);
  }
  const int max_radius = std::max(canvas.rows(), canvas.cols());
  for (int it = 0; it < options_.iterations && !top.best().empty(); ++it) {
    const Pixel best = top.best().front().source;
    for (const auto& [dr, dc] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}})
      offer(best.row + dr, best.col + dc);
    for (double radius = max_radius; radius >= 1.0; radius *= options_.alpha) {
      const int rad = static_cast<int>(radius);
      const Pixel center = top.best().front().source;
      offer(center.row + UniformInt(rng, 2 * rad + 1) - rad, center.col + UniformInt(rng, 2 * rad + 1) - rad);
    }
  }
  evaluations_ += evaluated;
  std::vector<SourceCandidate> result = top.best();
  if (!result.empty()) {
    recent_offsets_.insert(recent_offsets_.begin(), cv::Point(result.front().source.col - target.col,
                                                              result.front().source.row - target.row));
    if (recent_offsets_.size() > 8) recent_offsets_.pop_back();
  }
  return result;
}

}  // namespace lidarshop
