// The SSD kernels (baseline, AVX2, AVX-512) agree bit for bit: single candidates and runs of 1..9 adjacent
// candidates, with and without a bound, channel counts 1..7, radii whose rows are not multiples of 8 floats
// (nor of 16: the AVX-512 kernel reads one 8-float block past odd spans), masks at the image's edges, and whole
// fills.
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/util/simd.h"

namespace lidarshop {
namespace {

// Skips the test when the CPU lacks the path's instruction set.
#define REQUIRE_AVX2() \
  if (BestSimdPath() != SimdPath::kAvx2) GTEST_SKIP() << "this CPU has no AVX2"

cv::Mat RandomSignedImage(int rows, int cols, int channels, uint64_t seed) {
  cv::Mat image(rows, cols, CV_32FC(channels));
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, -50.0, 255.0);
  return image;
}

// Two holes: a blob touching the top-left corner (targets at the image's edges) and one inside.
cv::Mat Holes(int rows, int cols) {
  cv::Mat mask = cv::Mat::zeros(rows, cols, CV_8U);
  cv::circle(mask, {1, 2}, 6, cv::Scalar(255), cv::FILLED);
  cv::circle(mask, {cols / 2, rows / 2}, 5, cv::Scalar(255), cv::FILLED);
  return mask;
}

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The vector kernels this CPU runs.
std::vector<SsdKernel> VectorKernels() {
  std::vector<SsdKernel> kernels;
  for (const SsdKernel k : {SsdKernel::kAvx2, SsdKernel::kAvx512})
    if (k <= BestSsdKernel()) kernels.push_back(k);
  return kernels;
}

TEST(PatchDifferencePaths, KernelNames) {
  EXPECT_STREQ(WeightedSsd({}, SimdPath::kScalar).KernelName(), "baseline");
  EXPECT_STREQ(WeightedSsd({}, SsdKernel::kBaseline).KernelName(), "baseline");
  REQUIRE_AVX2();
  EXPECT_STREQ(WeightedSsd({}, SsdKernel::kAvx2).KernelName(), "avx2");
  // SimdPath::kAvx2 takes the widest kernel the CPU runs.
  EXPECT_STREQ(WeightedSsd({}, SimdPath::kAvx2).KernelName(),
               BestSsdKernel() == SsdKernel::kAvx512 ? "avx512" : "avx2");
  EXPECT_STREQ(WeightedSsd({}, SsdKernel::kAvx512).KernelName(),
               BestSsdKernel() == SsdKernel::kAvx512 ? "avx512" : "avx2");
}

TEST(PatchDifferencePaths, EveryKernelBitIdentical) {
  REQUIRE_AVX2();
  std::mt19937 rng(20261124);
  int compared = 0, above_bound = 0;
  for (int channels = 1; channels <= 7; ++channels) {
    for (int radius : {1, 2, 3, 4}) {  // rows of 3..9 pixels: 3..63 floats, mostly not multiples of 8
      const int rows = 31, cols = 37;
      const cv::Mat image = RandomSignedImage(rows, cols, channels, 100 * channels + radius);
      const InpaintCanvas canvas(image, Holes(rows, cols), radius);
      std::vector<float> weights;  // all 1, unequal, and one zero weight in turn
      if (channels > 1 && radius % 2 == 0) {
        std::uniform_real_distribution<float> weight(0.1f, 3.0f);
        for (int k = 0; k < channels; ++k) weights.push_back(k == 1 && radius == 4 ? 0.0f : weight(rng));
      }
      const WeightedSsd baseline(weights, SsdKernel::kBaseline);
      for (const SsdKernel kernel : VectorKernels()) {
        const WeightedSsd avx2(weights, kernel);
        // Targets: every hole-border pixel (known and unknown pixels in the patch, patches cut by the edges).
        for (int r = 0; r < rows; ++r) {
          for (int c = 0; c < cols; ++c) {
            if (canvas.IsKnown(r, c) || (r % 2 + c % 3) != 0) continue;
            const auto a = baseline.ForTarget(canvas, {r, c});
            const auto b = avx2.ForTarget(canvas, {r, c});
            for (int sr = 0; sr < rows; sr += 3) {
              const auto& source_cols = canvas.source_cols_by_row()[sr];
              for (size_t i = 0; i < source_cols.size(); ++i) {
                const Pixel source{sr, source_cols[i]};
                const float full_a = a->Evaluate(source, std::numeric_limits<float>::infinity());
                const float full_b = b->Evaluate(source, std::numeric_limits<float>::infinity());
                ASSERT_TRUE(SameBits(full_a, full_b))
                    << full_a << " vs " << full_b << " channels " << channels;
                ++compared;
                // A bound below the value: early termination must stop at the same row with the same sum.
                const float bound = full_a * 0.3f;
                const float bounded_a = a->Evaluate(source, bound), bounded_b = b->Evaluate(source, bound);
                ASSERT_TRUE(SameBits(bounded_a, bounded_b));
                above_bound += bounded_a > bound;
                // Runs of every length 1..9 that stay in one stretch of adjacent source centres.
                int length = 1;
                while (i + length < source_cols.size() && source_cols[i + length] == source.col + length &&
                       length < 9)
                  ++length;
                for (int count = 1; count <= length; ++count) {
                  for (const float run_bound : {std::numeric_limits<float>::infinity(), bound}) {
                    float out_a[9], out_b[9];
                    a->EvaluateRun(source, count, run_bound, out_a);
                    b->EvaluateRun(source, count, run_bound, out_b);
                    for (int k = 0; k < count; ++k)
                      ASSERT_TRUE(SameBits(out_a[k], out_b[k]))
                          << out_a[k] << " vs " << out_b[k] << " run " << count << " channels " << channels
                          << " kernel " << avx2.KernelName();
                  }
                }
              }
            }
          }
        }
      }
    }
  }
  EXPECT_GT(compared, 10000);
  EXPECT_GT(above_bound, compared / 2);  // the bounded evaluations did terminate early
}

TEST(PatchDifferencePaths, WholeFillBitIdentical) {
  REQUIRE_AVX2();
  for (int channels : {1, 3, 5}) {
    const cv::Mat image = RandomSignedImage(60, 70, channels, 7 + channels);
    cv::Mat smooth;
    cv::GaussianBlur(image, smooth, cv::Size(7, 7), 2.0);
    cv::Mat mask = cv::Mat::zeros(60, 70, CV_8U);
    cv::circle(mask, {3, 30}, 9, cv::Scalar(255), cv::FILLED);
    cv::rectangle(mask, cv::Rect(35, 20, 12, 9), cv::Scalar(255), cv::FILLED);
    InpaintOptions options;
    options.patch_radius = 4;
    std::vector<cv::Mat> filled;
    std::vector<SsdKernel> kernels = VectorKernels();
    kernels.insert(kernels.begin(), SsdKernel::kBaseline);
    for (const SsdKernel kernel : kernels) {
      InpaintStrategies strategies;
      strategies.difference = std::make_unique<WeightedSsd>(options.channel_weights, kernel);
      filled.push_back(Inpaint(smooth, mask, options, std::move(strategies)).image);
    }
    for (size_t i = 1; i < filled.size(); ++i) {
      ASSERT_EQ(filled[0].size(), filled[i].size());
      EXPECT_EQ(std::memcmp(filled[0].data, filled[i].data, filled[0].total() * filled[0].elemSize()), 0)
          << "channels " << channels << " kernel " << static_cast<int>(kernels[i]);
    }
    EXPECT_EQ(cv::norm(filled[0], smooth, cv::NORM_INF, mask == 0), 0.0);  // known pixels untouched
  }
}

}  // namespace
}  // namespace lidarshop
