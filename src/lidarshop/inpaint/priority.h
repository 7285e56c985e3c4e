// Patch priorities: which front pixel's patch is filled next (higher first).
//
// The fill loop caches the priority of every front pixel and, after each fill, asks again only for front
// pixels within InfluenceRadius() of the filled patch's bounding box; a priority must therefore depend only
// on the canvas within that radius of the pixel (the loop's check_bookkeeping mode verifies this against a
// full recomputation).
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/inpaint/canvas.h"

namespace lidarshop {

class PatchPriority {
 public:
  virtual ~PatchPriority() = default;
  // Called once before the first fill.
  virtual void Initialize(const InpaintCanvas& canvas) = 0;
  // Called after `target`'s patch was filled; `filled` are the pixels that became known.
  virtual void Update(const InpaintCanvas& canvas, Pixel target, const std::vector<Pixel>& filled) = 0;
  // Priority of a front pixel.
  virtual double Priority(const InpaintCanvas& canvas, Pixel pixel) const = 0;
  // Pixels whose priority may change when a pixel at distance d (Chebyshev) is filled:
  // d <= InfluenceRadius().
  virtual int InfluenceRadius(const InpaintCanvas& canvas) const = 0;
  // Verifies incrementally kept state against a recomputation from scratch;
  // throws std::logic_error on mismatch.
  virtual void CheckConsistency(const InpaintCanvas& canvas) const {}
};

// A pseudo-random priority per pixel, a pure function of (seed, pixel): independent of the fill history.
class RandomPriority : public PatchPriority {
 public:
  explicit RandomPriority(uint64_t seed) : seed_(seed) {}
  void Initialize(const InpaintCanvas&) override {}
  void Update(const InpaintCanvas&, Pixel, const std::vector<Pixel>&) override {}
  double Priority(const InpaintCanvas& canvas, Pixel pixel) const override;
  int InfluenceRadius(const InpaintCanvas&) const override { return 0; }

 private:
  uint64_t seed_;
};

// Confidence term of Criminisi et al. 2004, eq. 2:  C(p) = Σ_{q ∈ Ψp ∩ known} C(q) / |Ψp|, with C = 1 on the
// original known region and, after each fill, C(q) = C(p̂) for the filled pixels q of the chosen patch p̂.
// |Ψp| counts the patch pixels inside the image (so border patches are not penalised).
class ConfidenceMap {
 public:
  void Initialize(const InpaintCanvas& canvas);
  void Update(const InpaintCanvas& canvas, Pixel target, const std::vector<Pixel>& filled);
  double Confidence(const InpaintCanvas& canvas, Pixel pixel) const;
  const cv::Mat& confidence() const { return confidence_; }  // H x W CV_64F

 private:
  cv::Mat confidence_;
};

// Onion peel: priority = confidence alone, so the fill proceeds in layers from the hole's rim inwards.
class OnionPeelPriority : public PatchPriority {
 public:
  void Initialize(const InpaintCanvas& canvas) override { confidence_.Initialize(canvas); }
  void Update(const InpaintCanvas& canvas, Pixel target, const std::vector<Pixel>& filled) override {
    confidence_.Update(canvas, target, filled);
  }
  double Priority(const InpaintCanvas& canvas, Pixel pixel) const override {
    return confidence_.Confidence(canvas, pixel);
  }
  int InfluenceRadius(const InpaintCanvas& canvas) const override { return canvas.patch_radius(); }

 private:
  ConfidenceMap confidence_;
};

struct CriminisiPriorityOptions {
  double normal_sigma = 1.5;  // pixels; Gaussian blur of the hole mask whose gradient gives the front normal
  double alpha = 255.0;       // image units; normalises the data term (255 for 8-bit intensities)
  double data_floor = 1e-3;   // added to the data term so that flat regions still fill by confidence
  std::vector<float>
      channel_weights;  // empty = all 1; channels are averaged with these weights for gradients
  void Check() const;
};

// Criminisi, Pérez, Toyama 2004, eq. 1:  P(p) = C(p) · D(p),  D(p) = |∇I⊥_p · n_p| / α  (+ data_floor).
// ∇I_p is the largest-magnitude image gradient over the known pixels of Ψp, computed by KnownGradient (which
// never reads hole pixels); n_p is the unit gradient of the Gaussian-blurred hole mask at p (it points into
// the hole).
class CriminisiPriority : public PatchPriority {
 public:
  explicit CriminisiPriority(CriminisiPriorityOptions options);
  void Initialize(const InpaintCanvas& canvas) override;
  void Update(const InpaintCanvas& canvas, Pixel target, const std::vector<Pixel>& filled) override;
  double Priority(const InpaintCanvas& canvas, Pixel pixel) const override;
  int InfluenceRadius(const InpaintCanvas& canvas) const override;
  void CheckConsistency(const InpaintCanvas& canvas) const override;

  double DataTerm(const InpaintCanvas& canvas, Pixel pixel) const;
  cv::Vec2d Normal(Pixel pixel) const;  // (d/drow, d/dcol), unit or zero
  double Confidence(const InpaintCanvas& canvas, Pixel pixel) const {
    return confidence_.Confidence(canvas, pixel);
  }

 private:
  int BlurRadius() const;
  CriminisiPriorityOptions options_;
  ConfidenceMap confidence_;
  cv::Mat hole_, blurred_hole_;  // H x W CV_32F, 1 = hole
};

// Gradient (d/drow, d/dcol) of the channel-weighted mean intensity at a known pixel, using only known pixels:
// central differences where both neighbours are known, one-sided differences where one is a hole or outside
// the image, 0 along an axis where neither is usable. Returns (0, 0) for a hole pixel.
cv::Vec2d KnownGradient(const InpaintCanvas& canvas, Pixel pixel, const std::vector<float>& channel_weights);

}  // namespace lidarshop
