// Patch acceptance tests (thesis ch. 7.1): is the best-SSD source patch really a good one to copy?
//
// A greedy fill trusts the patch with the least difference between the *known* pixels of the target Ψp and
// the same pixels of the source Ψq. That comparison never looks at what is copied: the pixels of Ψq at the
// target's hole positions. The tests here compare the target's known region K (offsets d with p+d known)
// with the source's copied region H (offsets d with p+d a hole pixel, read from q+d), optionally also K with
// the source's own pixels at K, and optionally only in thin bands along the hole boundary (fig. 7.4).
//
// Every test works on any channel count: differences are taken per channel in units of the channel's value
// range over the known pixels of the canvas (so a threshold of 0.1 means "a tenth of the range"), and
// channels are averaged with the channel weights. Each test is its own part with its own options; the
// combined acceptance ANDs the enabled ones and accepts automatically when the hole covers less than
// `auto_accept_hole_fraction` of the patch. A rejection names the test, its value and its threshold.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "lidarshop/inpaint/canvas.h"
#include "lidarshop/inpaint/search.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// The outcome of one acceptance test, or of all of them. margin = (threshold − value) / threshold of the
// test closest to failing: > 0 passes (larger = more clearly), <= 0 fails.
struct AcceptanceVerdict {
  bool accepted = true;
  double margin = 1.0;
  std::string test;  // the test that decided (the failing one, or the one with the least margin)
  double value = 0.0, threshold = 0.0;
  // A rejection no fallback overrides: when no candidate passes, the fill copies the best candidate that was
  // not rejected outright (e.g. one that would bring sky into a wall, fill/return_acceptance.h).
  bool hard = false;
  std::string Explain() const;  // e.g. "rejected by mean: 0.31 > 0.15"
};

// The acceptance hook of the fill loop. Called with candidates in ranked order; must be deterministic and
// thread-safe (const).
class PatchAcceptance {
 public:
  virtual ~PatchAcceptance() = default;
  // Called once per fill before the first Accept() (e.g. to measure the canvas's value ranges).
  virtual void Initialize(const InpaintCanvas& canvas) {}
  virtual bool Accept(const InpaintCanvas& canvas, Pixel target, const SourceCandidate& candidate) const = 0;
  // With a margin and an explanation; the default wraps Accept() (margin ±1).
  virtual AcceptanceVerdict Judge(const InpaintCanvas& canvas, Pixel target,
                                  const SourceCandidate& candidate) const;
};

// The pixel sets one comparison sees, per channel, gathered once per (target, candidate).
struct AcceptanceRegions {
  int channels = 0;
  std::vector<float> target_known;   // K: the target's known pixels, n_known x C, in range units
  std::vector<float> source_copied;  // H: the source's pixels at the target's hole offsets, n_copied x C
  std::vector<float> source_known;   // the source's pixels at K, n_known x C
  std::vector<int> known_quadrant;   // per K pixel: 0..3 = (row > centre ? 2 : 0) + (col > centre ? 1 : 0)
  std::vector<int> copied_quadrant;  // per H pixel
  int patch_pixels = 0;              // pixels of Ψp inside the image
  int hole_pixels = 0;               // hole pixels of Ψp (before any band restriction)
  int known_count() const { return channels ? static_cast<int>(target_known.size()) / channels : 0; }
  int copied_count() const { return channels ? static_cast<int>(source_copied.size()) / channels : 0; }
};

// One region as a test sees it: count x channels values in range units, and each pixel's quadrant.
struct RegionView {
  const float* values = nullptr;
  const int* quadrant = nullptr;
  int count = 0;
  int channels = 0;
};

// Per channel, the least value over the canvas's known pixels and the value range (max − min, at least
// 1e-6; 1 for a canvas without known pixels): the unit of every acceptance test.
void ChannelRanges(const InpaintCanvas& canvas, std::vector<float>* low, std::vector<float>* range);

// The regions of (target, source) on `canvas`. band_px > 0 keeps only known pixels within band_px
// (Chebyshev) of a hole pixel of Ψp and hole pixels within band_px of a known one; 0 keeps all.
// range: per channel, the value range used as unit (> 0).
AcceptanceRegions GatherRegions(const InpaintCanvas& canvas, Pixel target, Pixel source, int band_px,
                                const std::vector<float>& channel_low,
                                const std::vector<float>& channel_range);

// One statistical comparison. Value() is a distance >= 0 (smaller = more alike), compared with Threshold().
class AcceptanceTest {
 public:
  virtual ~AcceptanceTest() = default;
  virtual const char* Name() const = 0;
  virtual double Threshold() const = 0;
  // Distance between the target's known region `known` and the compared region `other` (the copied pixels,
  // or the source's pixels at the known offsets); NaN = too few pixels to judge (counts as a pass).
  // channel_weights: one per channel, not all zero.
  virtual double Value(const RegionView& known, const RegionView& other,
                       const std::vector<float>& channel_weights) const = 0;
};

enum class HistogramRange { kFull, kCompressed };  // canvas value range, or the two regions' own range
enum class HistogramMetric { kIntersection, kEarthMovers };

// Each test's options. Thresholds are in units of the channel value range (mean, representative) or are
// normalised distances in [0, 1] (histograms).
struct MeanTestOptions {
  bool enabled = false;
  double max_difference = 0.12;  // range units; weighted RMS over channels of |mean K − mean H|
};
struct RepresentativeTestOptions {
  bool enabled = false;
  double max_difference = 0.15;  // range units; |median K − median H| (per-channel median as the MPEG-7
                                 // "representative colour")
};
struct HistogramTestOptions {
  bool enabled = false;
  int bins = 16;                                 // per channel
  HistogramRange range = HistogramRange::kFull;  // kCompressed: bins span the two regions' min..max
  HistogramMetric metric = HistogramMetric::kEarthMovers;
  // Compare part by part (thesis fig. 7.8): the patch is split into four halves (top, bottom, left, right),
  // each compared on its own, the worst counts; parts with < 4 pixels of either region are skipped. (Proper
  // quadrants would see only one of the two regions whenever the hole boundary follows a quadrant edge.)
  bool quadrants = false;
  double max_distance = 0.15;  // intersection: 1 − Σ min(h1, h2); EMD: Σ|CDF1 − CDF2| / bins; both in [0, 1]
};
struct SmoothTextureTestOptions {
  bool enabled = false;
  // Rejects copying a flat region into a textured one: a flat patch at the texture's mean differs from a
  // textured target by variance σ² per pixel, a matching textured patch by 2σ², so SSD prefers the flat one
  // (thesis fig. 7.9). Value = 1 − σ_copied / σ_known (0 when the copied region is the rougher one, or when
  // σ_known <= texture_sigma: a smooth target may receive structure, e.g. an edge continuing into the hole).
  double texture_sigma = 0.02;  // range units: a known region below this counts as smooth
  double max_value = 0.6;       // reject when σ_copied < 0.4 σ_known
};

struct AcceptanceOptions {
  bool enabled = false;  // false = no acceptance (plain Criminisi); Combined() switches the default set on
  MeanTestOptions mean;
  RepresentativeTestOptions representative;
  HistogramTestOptions histogram;
  SmoothTextureTestOptions smooth_texture;
  int band_px = 0;  // > 0: compare only bands this wide along the hole boundary (thesis fig. 7.4)
  bool also_known_to_known = false;         // also compare K with the source's pixels at K (fig. 7.3a)
  double auto_accept_hole_fraction = 0.10;  // accept when hole pixels < this fraction of the patch
  int min_region_pixels = 4;                // fewer pixels in a region: the test passes (too few to judge)
  void Check() const;                       // throws OptionsError naming the field

  // The recommended combination (bench/results/inpaint.md): representative colour, half-patch EMD
  // histograms and smooth-versus-textured, on a 2-pixel band.
  static AcceptanceOptions Combined();
};

template <>
const EnumInfo& EnumInfoOf<HistogramRange>();
template <>
const EnumInfo& EnumInfoOf<HistogramMetric>();
template <>
const StructInfo& InfoOf<MeanTestOptions>();
template <>
const StructInfo& InfoOf<RepresentativeTestOptions>();
template <>
const StructInfo& InfoOf<HistogramTestOptions>();
template <>
const StructInfo& InfoOf<SmoothTextureTestOptions>();
template <>
const StructInfo& InfoOf<AcceptanceOptions>();

// All enabled tests of `options`, combined with AND. Initialize() must be called with the canvas first.
class CombinedAcceptance : public PatchAcceptance {
 public:
  CombinedAcceptance(AcceptanceOptions options, std::vector<float> channel_weights);
  void AddTest(std::unique_ptr<AcceptanceTest> test);  // pluggable: any further test
  bool Accept(const InpaintCanvas& canvas, Pixel target, const SourceCandidate& candidate) const override {
    return Judge(canvas, target, candidate).accepted;
  }
  AcceptanceVerdict Judge(const InpaintCanvas& canvas, Pixel target,
                          const SourceCandidate& candidate) const override;
  // Measures the canvas's per-channel value range over its known pixels (the unit of every test).
  void Initialize(const InpaintCanvas& canvas) override;
  size_t test_count() const { return tests_.size(); }

 private:
  AcceptanceOptions options_;
  std::vector<float> weights_;
  std::vector<std::unique_ptr<AcceptanceTest>> tests_;
  std::vector<float> low_, range_;
};

std::unique_ptr<AcceptanceTest> MakeMeanTest(const MeanTestOptions& options);
std::unique_ptr<AcceptanceTest> MakeRepresentativeTest(const RepresentativeTestOptions& options);
std::unique_ptr<AcceptanceTest> MakeHistogramTest(const HistogramTestOptions& options);
std::unique_ptr<AcceptanceTest> MakeSmoothTextureTest(const SmoothTextureTestOptions& options);

// The combined acceptance of `options`, or null when !options.enabled. channel_weights: empty = all 1.
std::unique_ptr<CombinedAcceptance> MakeAcceptance(const AcceptanceOptions& options,
                                                   const std::vector<float>& channel_weights = {});

}  // namespace lidarshop
