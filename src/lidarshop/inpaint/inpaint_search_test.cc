// Exactness of the patch difference and the searches against a brute-force double-precision reference.
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

cv::Mat RandomImage(int rows, int cols, int channels, uint64_t seed) {
  cv::Mat image(rows, cols, CV_32FC(channels));
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 255.0);
  // Smooth a little so that patches are not all equally far apart.
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.0);
  return image;
}

cv::Mat BlobMask(int rows, int cols, cv::Point center, int radius) {
  cv::Mat mask = cv::Mat::zeros(rows, cols, CV_8U);
  cv::circle(mask, center, radius, cv::Scalar(255), cv::FILLED);
  return mask;
}

// Brute force: Σ over known target pixels inside the image of Σ_k w_k (T − S)², in double.
double ReferenceSsd(const InpaintCanvas& canvas, Pixel target, Pixel source,
                    const std::vector<float>& weights) {
  const int R = canvas.patch_radius();
  double sum = 0.0;
  for (int dr = -R; dr <= R; ++dr) {
    for (int dc = -R; dc <= R; ++dc) {
      const int r = target.row + dr, c = target.col + dc;
      if (!canvas.Inside(r, c) || !canvas.IsKnown(r, c)) continue;
      const float* t = canvas.PixelData(r, c);
      const float* s = canvas.PixelData(source.row + dr, source.col + dc);
      for (int k = 0; k < canvas.channels(); ++k) {
        const double d = double{t[k]} - double{s[k]};
        sum += (weights.empty() ? 1.0 : weights[k]) * d * d;
      }
    }
  }
  return sum;
}

std::vector<Pixel> FrontPixels(const InpaintCanvas& canvas) {
  const cv::Mat front = ComputeFillFront(canvas.known());
  std::vector<Pixel> pixels;
  for (int r = 0; r < front.rows; ++r)
    for (int c = 0; c < front.cols; ++c)
      if (front.at<uint8_t>(r, c)) pixels.push_back({r, c});
  return pixels;
}

TEST(InpaintSearch, WeightedSsdMatchesReference) {
  const std::vector<float> weights = {1.0f, 0.5f, 2.0f};
  for (int radius : {1, 3, 5, 7}) {
    const cv::Mat image = RandomImage(50, 60, 3, 7);
    const InpaintCanvas canvas(image, BlobMask(50, 60, {3, 25}, 9), radius);  // touches the left border
    const WeightedSsd ssd(weights);
    for (const Pixel& target : FrontPixels(canvas)) {
      const auto prepared = ssd.ForTarget(canvas, target);
      for (size_t i = 0; i < canvas.source_centers().size(); i += 97) {
        const Pixel source = canvas.source_centers()[i];
        const double reference = ReferenceSsd(canvas, target, source, weights);
        const float fast = prepared->Evaluate(source, std::numeric_limits<float>::infinity());
        ASSERT_NEAR(fast, reference, 1e-5 * reference + 1e-3) << "radius " << radius;
        // Early termination returns something above a bound below the true value, the true value otherwise.
        EXPECT_GT(prepared->Evaluate(source, static_cast<float>(0.5 * reference)), 0.5 * reference);
        EXPECT_NEAR(prepared->Evaluate(source, static_cast<float>(2.0 * reference + 1.0)), reference,
                    1e-5 * reference + 1e-3);
      }
    }
  }
}

// EvaluateRun (several adjacent candidates per pass) returns bit-identical values to Evaluate, for equal,
// unequal and partly zero channel weights, 1 and 3 channels, radii whose rows need 1 to 5 SIMD vectors, and
// targets at the border; with a finite bound, a value <= bound is the exact one and anything else is > bound.
TEST(InpaintSearch, EvaluateRunMatchesEvaluate) {
  const std::vector<std::vector<float>> weight_sets = {
      {}, {2.0f, 2.0f, 2.0f}, {1.0f, 0.5f, 2.0f}, {0.0f, 3.0f, 3.0f}};
  for (int channels : {1, 3}) {
    for (int radius : {1, 2, 5, 7, 10, 11}) {
      const cv::Mat image = RandomImage(50, 70, channels, 5);
      const InpaintCanvas canvas(image, BlobMask(50, 70, {3, 30}, 9), radius);
      for (const auto& weights : weight_sets) {
        if (channels == 1 && !weights.empty()) continue;
        const WeightedSsd ssd(weights);
        const auto front = FrontPixels(canvas);
        for (size_t f = 0; f < front.size(); f += 5) {
          const auto prepared = ssd.ForTarget(canvas, front[f]);
          for (int r = 0; r < canvas.rows(); r += 7) {
            const auto& cols = canvas.source_cols_by_row()[r];
            for (size_t i = 0; i + 6 <= cols.size() && cols[i + 5] == cols[i] + 5; i += 11) {
              if (!canvas.SourceFits(front[f], {r, cols[i]}) ||
                  !canvas.SourceFits(front[f], {r, cols[i] + 5}))
                continue;
              float run[6];
              prepared->EvaluateRun({r, cols[i]}, 6, std::numeric_limits<float>::infinity(), run);
              for (int k = 0; k < 6; ++k) {
                const float one =
                    prepared->Evaluate({r, cols[i] + k}, std::numeric_limits<float>::infinity());
                ASSERT_EQ(run[k], one) << "radius " << radius << " channels " << channels;
                ASSERT_NEAR(one, ReferenceSsd(canvas, front[f], {r, cols[i] + k}, weights),
                            1e-5 * one + 1e-3);
              }
              const float bound = run[2];
              float bounded[6];
              prepared->EvaluateRun({r, cols[i]}, 6, bound, bounded);
              for (int k = 0; k < 6; ++k) {
                if (run[k] <= bound) {
                  EXPECT_EQ(bounded[k], run[k]);
                } else {
                  EXPECT_GT(bounded[k], bound);
                }
              }
            }
          }
        }
      }
    }
  }
}

TEST(InpaintSearch, ExhaustiveFindsTheTrueMinimum) {
  const cv::Mat image = RandomImage(64, 80, 3, 11);
  const InpaintCanvas canvas(image, BlobMask(64, 80, {40, 30}, 10), 5);
  const WeightedSsd ssd;
  ExhaustiveSearch search;
  int same_index = 0, targets = 0;
  for (const Pixel& target : FrontPixels(canvas)) {
    const auto prepared = ssd.ForTarget(canvas, target);
    // Brute force ranking in double.
    std::vector<std::pair<double, int>> reference;
    for (size_t i = 0; i < canvas.source_centers().size(); ++i) {
      reference.push_back(
          {ReferenceSsd(canvas, target, canvas.source_centers()[i], {}), static_cast<int>(i)});
    }
    std::sort(reference.begin(), reference.end());
    const auto found = search.Find(canvas, *prepared, target, 5);
    ASSERT_EQ(found.size(), 5u);
    for (int k = 0; k < 5; ++k) {
      // The k-th found patch has the k-th smallest true SSD (to float rounding).
      const double true_ssd = ReferenceSsd(canvas, target, found[k].source, {});
      EXPECT_NEAR(true_ssd, reference[k].first, 1e-5 * reference[k].first + 1e-3);
      if (k > 0) EXPECT_FALSE(CandidateBefore(found[k], found[k - 1]));
    }
    const Pixel best = canvas.source_centers()[reference[0].second];
    same_index += found[0].source == best ? 1 : 0;
    ++targets;
  }
  // Random textures have no ties, so the very same patch must come back.
  EXPECT_EQ(same_index, targets);
}

TEST(InpaintSearch, ExhaustiveDoesNotDependOnThreads) {
  const cv::Mat image = RandomImage(90, 90, 3, 3);
  const InpaintCanvas canvas(image, BlobMask(90, 90, {45, 45}, 12), 5);
  const WeightedSsd ssd;
  for (const Pixel& target : FrontPixels(canvas)) {
    const auto prepared = ssd.ForTarget(canvas, target);
    std::vector<SourceCandidate> one, two;
    {
      ThreadLimit limit(1);
      ExhaustiveSearch search;
      one = search.Find(canvas, *prepared, target, 3);
    }
    {
      ThreadLimit limit(2);
      ExhaustiveSearch search;
      two = search.Find(canvas, *prepared, target, 3);
    }
    ASSERT_EQ(one.size(), two.size());
    for (size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(one[i].source, two[i].source);
      EXPECT_EQ(one[i].difference, two[i].difference);
    }
  }
}

// The pruned scans (early termination against a bound shared between row chunks and threads, rows from the
// window's middle out, a first bound from the nearby window) return exactly what scoring every candidate in
// full and ranking by CandidateBefore returns: the same sources, the same bits, ties in the same order. The
// image repeats with a period of 7 pixels in parts, so many candidates tie exactly.
TEST(InpaintSearch, PrunedScanEqualsFullRanking) {
  cv::Mat image = RandomImage(120, 130, 3, 17);
  for (int r = 0; r < image.rows; ++r)
    for (int c = 60; c < image.cols; ++c) image.at<cv::Vec3f>(r, c) = image.at<cv::Vec3f>(r % 7, 60 + c % 7);
  const InpaintCanvas canvas(image, BlobMask(120, 130, {62, 60}, 14), 4);
  const WeightedSsd ssd({1.0f, 0.5f, 2.0f});
  const int count = 8, radius = 25;
  int targets = 0, ties = 0;
  const auto front = FrontPixels(canvas);
  for (size_t f = 0; f < front.size(); f += 3) {
    const Pixel target = front[f];
    const auto prepared = ssd.ForTarget(canvas, target);
    std::vector<SourceCandidate> all;
    for (const Pixel& s : canvas.source_centers()) {
      if (std::abs(s.row - target.row) > radius || std::abs(s.col - target.col) > radius) continue;
      all.push_back({s, prepared->Evaluate(s, std::numeric_limits<float>::infinity())});
    }
    std::sort(all.begin(), all.end(), CandidateBefore);
    ASSERT_GE(all.size(), static_cast<size_t>(count));
    all.resize(count);
    for (int k = 1; k < count; ++k) ties += all[k].difference == all[k - 1].difference;
    for (int threads : {1, 2}) {
      ThreadLimit limit(threads);
      ExhaustiveSearch search;
      const auto near = search.FindNear(canvas, *prepared, target, count, radius);
      const auto below = search.FindBelow(
          canvas, *prepared, target, count, std::numeric_limits<float>::infinity(), target.row - radius,
          target.row + radius + 1, target.col - radius, target.col + radius + 1);
      for (const auto* found : {&near, &below}) {
        ASSERT_EQ(found->size(), all.size()) << "threads " << threads;
        for (int k = 0; k < count; ++k) {
          EXPECT_EQ((*found)[k].source, all[k].source) << "rank " << k << ", threads " << threads;
          EXPECT_EQ((*found)[k].difference, all[k].difference);
        }
      }
    }
    ++targets;
  }
  EXPECT_GT(targets, 10);
  EXPECT_GT(ties, 0);  // the periodic part did produce exact ties
}

TEST(InpaintSearch, TwoStepWithUnitGainIsExact) {
  const cv::Mat image = RandomImage(80, 100, 3, 5);
  const InpaintCanvas canvas(image, BlobMask(80, 100, {50, 40}, 11), 4);
  const WeightedSsd ssd;
  ExhaustiveSearch exhaustive;
  TwoStepSearch two_step(10, 1.0);
  for (const Pixel& target : FrontPixels(canvas)) {
    const auto prepared = ssd.ForTarget(canvas, target);
    const auto a = exhaustive.Find(canvas, *prepared, target, 1);
    const auto b = two_step.Find(canvas, *prepared, target, 1);
    ASSERT_EQ(a.size(), 1u);
    ASSERT_EQ(b.size(), 1u);
    EXPECT_EQ(a[0].source, b[0].source);
  }
  // It prunes: fewer full evaluations are needed, but each candidate is still offered.
  EXPECT_GT(two_step.evaluations(), 0);
}

TEST(InpaintSearch, LocalSearchStaysInItsWindow) {
  const cv::Mat image = RandomImage(80, 100, 3, 5);
  const InpaintCanvas canvas(image, BlobMask(80, 100, {50, 40}, 11), 4);
  const WeightedSsd ssd;
  LocalSearch local(12);
  for (const Pixel& target : FrontPixels(canvas)) {
    const auto found = local.Find(canvas, *ssd.ForTarget(canvas, target), target, 2);
    ASSERT_EQ(found.size(), 2u);
    for (const auto& c : found) {
      EXPECT_LE(std::abs(c.source.row - target.row), 12);
      EXPECT_LE(std::abs(c.source.col - target.col), 12);
    }
  }
}

// PatchMatch is approximate: report how often it finds the exhaustive answer and
// how much worse it is otherwise.
TEST(InpaintSearch, PatchMatchAgreementIsReported) {
  // A structured image (stripes + noise) where good matches exist and can be found by propagation.
  cv::Mat image(96, 128, CV_32FC3);
  cv::RNG rng(9);
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) {
      const float v = 128.0f + 100.0f * std::sin(0.4f * c + 0.15f * r);
      image.at<cv::Vec3f>(r, c) =
          cv::Vec3f(v, 255.0f - v, 0.5f * v) + cv::Vec3f(rng.gaussian(3), rng.gaussian(3), 0);
    }
  const InpaintCanvas canvas(image, BlobMask(96, 128, {64, 48}, 14), 5);
  const WeightedSsd ssd;
  ExhaustiveSearch exhaustive;
  PatchMatchSearch patchmatch(PatchMatchOptions{});
  int same = 0, total = 0;
  double worst_ratio = 1.0, ratio_sum = 0.0;
  for (const Pixel& target : FrontPixels(canvas)) {
    const auto prepared = ssd.ForTarget(canvas, target);
    const auto a = exhaustive.Find(canvas, *prepared, target, 1);
    const auto b = patchmatch.Find(canvas, *prepared, target, 1);
    ASSERT_EQ(b.size(), 1u);
    ++total;
    if (a[0].source == b[0].source) {
      ++same;
    } else {
      const double ratio = b[0].difference / std::max(1e-6f, a[0].difference);
      EXPECT_GE(ratio, 1.0 - 1e-6);  // never better than the exact minimum
      worst_ratio = std::max(worst_ratio, ratio);
      ratio_sum += ratio;
    }
  }
  const double per_query = static_cast<double>(patchmatch.evaluations()) / total;
  std::printf(
      "PatchMatch: same patch as exhaustive for %d of %d targets; SSD ratio when not: mean %.3f, worst %.3f; "
      "%.0f evaluations per query vs %zu exhaustive\n",
      same, total, total > same ? ratio_sum / (total - same) : 1.0, worst_ratio, per_query,
      canvas.source_centers().size());
  EXPECT_LT(per_query, 0.1 * canvas.source_centers().size());
  EXPECT_LT(worst_ratio, 10.0);
}

}  // namespace
}  // namespace lidarshop
