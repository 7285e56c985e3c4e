#include "lidarshop/inpaint/acceptance.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

std::string AcceptanceVerdict::Explain() const {
  if (test.empty()) return accepted ? "accepted" : "rejected";
  return fmt::format("{} by {}: {:.3g} {} {:.3g}", accepted ? "accepted" : "rejected", test, value,
                     accepted ? "<=" : ">", threshold);
}

AcceptanceVerdict PatchAcceptance::Judge(const InpaintCanvas& canvas, Pixel target,
                                         const SourceCandidate& candidate) const {
  AcceptanceVerdict verdict;
  verdict.accepted = Accept(canvas, target, candidate);
  verdict.margin = verdict.accepted ? 1.0 : -1.0;
  return verdict;
}

AcceptanceRegions GatherRegions(const InpaintCanvas& canvas, Pixel target, Pixel source, int band_px,
                                const std::vector<float>& channel_low,
                                const std::vector<float>& channel_range) {
  const int R = canvas.patch_radius(), C = canvas.channels();
  AcceptanceRegions regions;
  regions.channels = C;
  // Known / hole / outside per patch offset.
  const int w = 2 * R + 1;
  std::vector<int8_t> state(w * w, -1);  // -1 outside the image, 0 hole, 1 known
  for (int dr = -R; dr <= R; ++dr) {
    for (int dc = -R; dc <= R; ++dc) {
      const int r = target.row + dr, c = target.col + dc;
      if (!canvas.Inside(r, c)) continue;
      const bool known = canvas.IsKnown(r, c);
      state[(dr + R) * w + dc + R] = known ? 1 : 0;
      ++regions.patch_pixels;
      regions.hole_pixels += known ? 0 : 1;
    }
  }
  // Within band_px of a pixel of the other kind (Chebyshev), or everything when band_px == 0.
  auto in_band = [&](int i, int j, int8_t other) {
    if (band_px <= 0) return true;
    for (int a = std::max(0, i - band_px); a <= std::min(w - 1, i + band_px); ++a)
      for (int b = std::max(0, j - band_px); b <= std::min(w - 1, j + band_px); ++b)
        if (state[a * w + b] == other) return true;
    return false;
  };
  auto push = [&](std::vector<float>& out, const float* pixel) {
    for (int k = 0; k < C; ++k) out.push_back((pixel[k] - channel_low[k]) / channel_range[k]);
  };
  for (int i = 0; i < w; ++i) {
    for (int j = 0; j < w; ++j) {
      const int8_t s = state[i * w + j];
      if (s < 0 || !in_band(i, j, static_cast<int8_t>(1 - s))) continue;
      const int quadrant = (i > R ? 2 : 0) + (j > R ? 1 : 0);
      const float* from_source = canvas.PixelData(source.row + i - R, source.col + j - R);
      if (s == 1) {
        push(regions.target_known, canvas.PixelData(target.row + i - R, target.col + j - R));
        push(regions.source_known, from_source);
        regions.known_quadrant.push_back(quadrant);
      } else {
        push(regions.source_copied, from_source);
        regions.copied_quadrant.push_back(quadrant);
      }
    }
  }
  return regions;
}

void ChannelRanges(const InpaintCanvas& canvas, std::vector<float>* low, std::vector<float>* range) {
  const int C = canvas.channels();
  low->assign(C, std::numeric_limits<float>::infinity());
  std::vector<float> high(C, -std::numeric_limits<float>::infinity());
  for (int r = 0; r < canvas.rows(); ++r)
    for (int c = 0; c < canvas.cols(); ++c) {
      if (!canvas.IsKnown(r, c)) continue;
      const float* p = canvas.PixelData(r, c);
      for (int k = 0; k < C; ++k) {
        (*low)[k] = std::min((*low)[k], p[k]);
        high[k] = std::max(high[k], p[k]);
      }
    }
  range->resize(C);
  for (int k = 0; k < C; ++k) {
    if (!std::isfinite((*low)[k])) (*low)[k] = 0.0f, high[k] = 1.0f;
    (*range)[k] = std::max(high[k] - (*low)[k], 1e-6f);
  }
}

namespace {

double WeightSum(const std::vector<float>& weights) {
  double sum = 0.0;
  for (float w : weights) sum += w;
  return sum;
}

std::vector<double> ChannelMeans(const RegionView& region) {
  std::vector<double> mean(region.channels, 0.0);
  for (int i = 0; i < region.count; ++i)
    for (int k = 0; k < region.channels; ++k) mean[k] += region.values[i * region.channels + k];
  for (double& m : mean) m /= std::max(region.count, 1);
  return mean;
}

double ChannelMedian(const RegionView& region, int k, std::vector<float>& scratch) {
  scratch.clear();
  for (int i = 0; i < region.count; ++i) scratch.push_back(region.values[i * region.channels + k]);
  const size_t mid = scratch.size() / 2;
  std::nth_element(scratch.begin(), scratch.begin() + mid, scratch.end());
  return scratch[mid];
}

// Weighted RMS over channels of the difference of a per-channel centre: the mean ("mean") or the median
// ("representative", the MPEG-7 representative colour).
class CentreTest : public AcceptanceTest {
 public:
  CentreTest(bool median, double max_difference) : median_(median), max_difference_(max_difference) {}
  const char* Name() const override { return median_ ? "representative" : "mean"; }
  double Threshold() const override { return max_difference_; }
  double Value(const RegionView& a, const RegionView& b, const std::vector<float>& w) const override {
    std::vector<double> ca = ChannelMeans(a), cb = ChannelMeans(b);
    if (median_) {
      std::vector<float> scratch;
      for (int k = 0; k < a.channels; ++k) {
        ca[k] = ChannelMedian(a, k, scratch);
        cb[k] = ChannelMedian(b, k, scratch);
      }
    }
    double sum = 0.0;
    for (int k = 0; k < a.channels; ++k) sum += w[k] * (ca[k] - cb[k]) * (ca[k] - cb[k]);
    return std::sqrt(sum / WeightSum(w));
  }

 private:
  bool median_;
  double max_difference_;
};

class HistogramTest : public AcceptanceTest {
 public:
  explicit HistogramTest(HistogramTestOptions options) : options_(options) {}
  const char* Name() const override {
    if (options_.quadrants) return "histogram-quadrants";
    return options_.range == HistogramRange::kFull ? "histogram" : "histogram-compressed";
  }
  double Threshold() const override { return options_.max_distance; }
  double Value(const RegionView& a, const RegionView& b, const std::vector<float>& w) const override {
    if (!options_.quadrants) return Distance(a, b, -1, w);
    double worst = std::nan("");
    for (int q = 0; q < 4; ++q) {
      const double d = Distance(a, b, q, w);
      if (!std::isnan(d) && !(d <= worst)) worst = d;
    }
    return worst;
  }

 private:
  // Pixel of quadrant code `code` in half h: 0 top, 1 bottom, 2 left, 3 right; -1 = the whole patch.
  static bool InHalf(int code, int h) {
    switch (h) {
      case 0:
        return (code & 2) == 0;
      case 1:
        return (code & 2) != 0;
      case 2:
        return (code & 1) == 0;
      case 3:
        return (code & 1) != 0;
    }
    return true;
  }
  // Weighted mean over channels of the histogram distance of the pixels of half q (-1 = all).
  double Distance(const RegionView& a, const RegionView& b, int q, const std::vector<float>& w) const {
    const int bins = options_.bins;
    std::vector<double> ha(bins), hb(bins);
    double total = 0.0;
    for (int k = 0; k < a.channels; ++k) {
      float low = 0.0f, high = 1.0f;
      if (options_.range == HistogramRange::kCompressed) {
        low = std::numeric_limits<float>::infinity();
        high = -low;
        for (const RegionView* r : {&a, &b})
          for (int i = 0; i < r->count; ++i) {
            if (!InHalf(r->quadrant[i], q)) continue;
            low = std::min(low, r->values[i * r->channels + k]);
            high = std::max(high, r->values[i * r->channels + k]);
          }
        // A region spread over less than one bin of the full range is not stretched further.
        if (high - low < 1.0f / bins) {
          const float mid = 0.5f * (low + high);
          low = mid - 0.5f / bins;
          high = mid + 0.5f / bins;
        }
      }
      const int na = Fill(a, q, k, low, high, ha), nb = Fill(b, q, k, low, high, hb);
      if (na < 4 || nb < 4) return std::nan("");
      double d = 0.0;
      if (options_.metric == HistogramMetric::kIntersection) {
        double common = 0.0;
        for (int i = 0; i < bins; ++i) common += std::min(ha[i] / na, hb[i] / nb);
        d = 1.0 - common;
      } else {
        double cdf = 0.0;
        for (int i = 0; i < bins; ++i) {
          cdf += ha[i] / na - hb[i] / nb;
          d += std::abs(cdf);
        }
        d /= bins;
      }
      total += w[k] * d;
    }
    return total / WeightSum(w);
  }

  int Fill(const RegionView& r, int q, int k, float low, float high, std::vector<double>& h) const {
    std::fill(h.begin(), h.end(), 0.0);
    const int bins = options_.bins;
    const float scale = bins / (high - low);
    int n = 0;
    for (int i = 0; i < r.count; ++i) {
      if (!InHalf(r.quadrant[i], q)) continue;
      const int bin = static_cast<int>((r.values[i * r.channels + k] - low) * scale);
      ++h[std::clamp(bin, 0, bins - 1)];
      ++n;
    }
    return n;
  }

  HistogramTestOptions options_;
};

class SmoothTextureTest : public AcceptanceTest {
 public:
  explicit SmoothTextureTest(SmoothTextureTestOptions options) : options_(options) {}
  const char* Name() const override { return "smooth-texture"; }
  double Threshold() const override { return options_.max_value; }
  double Value(const RegionView& a, const RegionView& b, const std::vector<float>& w) const override {
    const double known = Sigma(a, w), other = Sigma(b, w);
    if (known <= options_.texture_sigma) return 0.0;
    return std::max(0.0, 1.0 - other / known);
  }

 private:
  // Weighted RMS over channels of the per-channel standard deviation.
  static double Sigma(const RegionView& r, const std::vector<float>& w) {
    const std::vector<double> mean = ChannelMeans(r);
    double sum = 0.0;
    for (int k = 0; k < r.channels; ++k) {
      double var = 0.0;
      for (int i = 0; i < r.count; ++i) {
        const double d = r.values[i * r.channels + k] - mean[k];
        var += d * d;
      }
      sum += w[k] * var / std::max(r.count, 1);
    }
    return std::sqrt(sum / WeightSum(w));
  }

  SmoothTextureTestOptions options_;
};

}  // namespace

std::unique_ptr<AcceptanceTest> MakeMeanTest(const MeanTestOptions& o) {
  return std::make_unique<CentreTest>(false, o.max_difference);
}
std::unique_ptr<AcceptanceTest> MakeRepresentativeTest(const RepresentativeTestOptions& o) {
  return std::make_unique<CentreTest>(true, o.max_difference);
}
std::unique_ptr<AcceptanceTest> MakeHistogramTest(const HistogramTestOptions& o) {
  return std::make_unique<HistogramTest>(o);
}
std::unique_ptr<AcceptanceTest> MakeSmoothTextureTest(const SmoothTextureTestOptions& o) {
  return std::make_unique<SmoothTextureTest>(o);
}

void AcceptanceOptions::Check() const { Validate(*this); }

AcceptanceOptions AcceptanceOptions::Combined() {
  AcceptanceOptions options;
  options.enabled = true;
  options.representative.enabled = true;
  options.histogram.enabled = true;
  options.histogram.quadrants = true;
  options.smooth_texture.enabled = true;
  options.band_px = 2;
  return options;
}

CombinedAcceptance::CombinedAcceptance(AcceptanceOptions options, std::vector<float> channel_weights)
    : options_(std::move(options)), weights_(std::move(channel_weights)) {
  options_.Check();
  if (options_.mean.enabled) AddTest(MakeMeanTest(options_.mean));
  if (options_.representative.enabled) AddTest(MakeRepresentativeTest(options_.representative));
  if (options_.histogram.enabled) AddTest(MakeHistogramTest(options_.histogram));
  if (options_.smooth_texture.enabled) AddTest(MakeSmoothTextureTest(options_.smooth_texture));
}

void CombinedAcceptance::AddTest(std::unique_ptr<AcceptanceTest> test) { tests_.push_back(std::move(test)); }

void CombinedAcceptance::Initialize(const InpaintCanvas& canvas) {
  const int C = canvas.channels();
  if (weights_.empty()) weights_.assign(C, 1.0f);
  if (static_cast<int>(weights_.size()) != C || WeightSum(weights_) <= 0.0) {
    throw OptionsError(fmt::format("acceptance: {} channel weights (sum {}) for an image of {} channels",
                                   weights_.size(), WeightSum(weights_), C));
  }
  ChannelRanges(canvas, &low_, &range_);
}

AcceptanceVerdict CombinedAcceptance::Judge(const InpaintCanvas& canvas, Pixel target,
                                            const SourceCandidate& candidate) const {
  LIDARSHOP_CHECK(static_cast<int>(range_.size()) == canvas.channels());
  AcceptanceVerdict verdict;
  verdict.margin = std::numeric_limits<double>::infinity();
  if (tests_.empty()) return verdict;
  const AcceptanceRegions regions =
      GatherRegions(canvas, target, candidate.source, options_.band_px, low_, range_);
  if (regions.hole_pixels < options_.auto_accept_hole_fraction * regions.patch_pixels) {
    verdict.test = "small hole";
    verdict.margin = 1.0;
    return verdict;
  }
  const int C = regions.channels;
  const RegionView known{regions.target_known.data(), regions.known_quadrant.data(), regions.known_count(),
                         C};
  const RegionView copied{regions.source_copied.data(), regions.copied_quadrant.data(),
                          regions.copied_count(), C};
  const RegionView source_known{regions.source_known.data(), regions.known_quadrant.data(),
                                regions.known_count(), C};
  std::vector<const RegionView*> others;
  if (copied.count >= options_.min_region_pixels) others.push_back(&copied);
  if (options_.also_known_to_known) others.push_back(&source_known);
  if (known.count < options_.min_region_pixels) others.clear();
  for (const auto& test : tests_) {
    for (const RegionView* other : others) {
      const double value = test->Value(known, *other, weights_);
      if (std::isnan(value)) continue;
      const double margin = (test->Threshold() - value) / test->Threshold();
      if (margin < verdict.margin) {
        verdict.margin = margin;
        verdict.test = test->Name();
        verdict.value = value;
        verdict.threshold = test->Threshold();
        verdict.accepted = value <= test->Threshold();
      }
      if (!verdict.accepted) return verdict;  // AND: the first failure decides
    }
  }
  if (!std::isfinite(verdict.margin)) verdict.margin = 1.0;
  return verdict;
}

std::unique_ptr<CombinedAcceptance> MakeAcceptance(const AcceptanceOptions& options,
                                                   const std::vector<float>& channel_weights) {
  if (!options.enabled) return nullptr;
  return std::make_unique<CombinedAcceptance>(options, channel_weights);
}

}  // namespace lidarshop
