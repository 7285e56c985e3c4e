#include "lidarshop/inpaint/priority.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

double Intensity(const InpaintCanvas& canvas, int row, int col, const std::vector<float>& weights) {
  const float* p = canvas.PixelData(row, col);
  double sum = 0.0, weight_sum = 0.0;
  for (int k = 0; k < canvas.channels(); ++k) {
    const double w = weights.empty() ? 1.0 : weights[k];
    sum += w * p[k];
    weight_sum += w;
  }
  return weight_sum > 0.0 ? sum / weight_sum : 0.0;
}

}  // namespace

double RandomPriority::Priority(const InpaintCanvas& canvas, Pixel pixel) const {
  const uint64_t h =
      SplitMix64(seed_ ^ SplitMix64(static_cast<uint64_t>(canvas.Index(pixel.row, pixel.col))));
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

void ConfidenceMap::Initialize(const InpaintCanvas& canvas) { canvas.known().convertTo(confidence_, CV_64F); }

double ConfidenceMap::Confidence(const InpaintCanvas& canvas, Pixel pixel) const {
  const int R = canvas.patch_radius();
  double sum = 0.0;
  int area = 0;
  for (int r = std::max(0, pixel.row - R); r <= std::min(canvas.rows() - 1, pixel.row + R); ++r) {
    const double* row = confidence_.ptr<double>(r);
    for (int c = std::max(0, pixel.col - R); c <= std::min(canvas.cols() - 1, pixel.col + R); ++c) {
      sum += row[c];  // hole pixels hold 0
      ++area;
    }
  }
  return sum / area;
}

void ConfidenceMap::Update(const InpaintCanvas& canvas, Pixel target, const std::vector<Pixel>& filled) {
  // C(p̂) is evaluated before the filled pixels get theirs (they still hold 0).
  const double value = Confidence(canvas, target);
  for (const Pixel& q : filled) confidence_.at<double>(q.row, q.col) = value;
}

cv::Vec2d KnownGradient(const InpaintCanvas& canvas, Pixel pixel, const std::vector<float>& channel_weights) {
  const int r = pixel.row, c = pixel.col;
  if (!canvas.IsKnown(r, c)) return {0.0, 0.0};
  auto known = [&](int rr, int cc) { return canvas.Inside(rr, cc) && canvas.IsKnown(rr, cc); };
  auto value = [&](int rr, int cc) { return Intensity(canvas, rr, cc, channel_weights); };
  auto axis = [&](int dr, int dc) {
    const bool plus = known(r + dr, c + dc), minus = known(r - dr, c - dc);
    if (plus && minus) return 0.5 * (value(r + dr, c + dc) - value(r - dr, c - dc));
    if (plus) return value(r + dr, c + dc) - value(r, c);
    if (minus) return value(r, c) - value(r - dr, c - dc);
    return 0.0;
  };
  return {axis(1, 0), axis(0, 1)};
}

void CriminisiPriorityOptions::Check() const {
  CheckOption(normal_sigma > 0.0 && normal_sigma <= 50.0,
              fmt::format("CriminisiPriorityOptions.normal_sigma must be in (0, 50], got {}", normal_sigma));
  CheckOption(alpha > 0.0, fmt::format("CriminisiPriorityOptions.alpha must be > 0, got {}", alpha));
  CheckOption(data_floor >= 0.0,
              fmt::format("CriminisiPriorityOptions.data_floor must be >= 0, got {}", data_floor));
  for (float w : channel_weights)
    CheckOption(w >= 0.0f, "CriminisiPriorityOptions.channel_weights must be >= 0");
}

CriminisiPriority::CriminisiPriority(CriminisiPriorityOptions options) : options_(std::move(options)) {
  options_.Check();
}

int CriminisiPriority::BlurRadius() const { return static_cast<int>(std::ceil(3.0 * options_.normal_sigma)); }

int CriminisiPriority::InfluenceRadius(const InpaintCanvas& canvas) const {
  // Confidence reads Ψp (R); the gradients of Ψp read one pixel further (R+1); the normal reads the blurred
  // mask one pixel away, which reads the mask BlurRadius() further.
  return std::max(canvas.patch_radius() + 1, BlurRadius() + 1);
}

void CriminisiPriority::Initialize(const InpaintCanvas& canvas) {
  confidence_.Initialize(canvas);
  cv::Mat hole;
  cv::compare(canvas.known(), 0, hole, cv::CMP_EQ);
  hole.convertTo(hole_, CV_32F, 1.0 / 255.0);
  const int k = 2 * BlurRadius() + 1;
  cv::GaussianBlur(hole_, blurred_hole_, cv::Size(k, k), options_.normal_sigma, options_.normal_sigma,
                   cv::BORDER_REPLICATE);
}

void CriminisiPriority::Update(const InpaintCanvas& canvas, Pixel target, const std::vector<Pixel>& filled) {
  confidence_.Update(canvas, target, filled);
  if (filled.empty()) return;
  for (const Pixel& q : filled) hole_.at<float>(q.row, q.col) = 0.0f;
  // Re-blur the box the change can reach. On a sub-matrix OpenCV reads the parent's pixels beyond the box
  // (the border mode applies only at the real image border), so this equals a full re-blur on the box.
  const int R = canvas.patch_radius(), b = BlurRadius();
  const cv::Rect box = cv::Rect(target.col - R - b, target.row - R - b, 2 * (R + b) + 1, 2 * (R + b) + 1) &
                       cv::Rect(0, 0, canvas.cols(), canvas.rows());
  const int k = 2 * b + 1;
  cv::Mat blurred_box;
  cv::GaussianBlur(hole_(box), blurred_box, cv::Size(k, k), options_.normal_sigma, options_.normal_sigma,
                   cv::BORDER_REPLICATE);
  blurred_box.copyTo(blurred_hole_(box));
}

cv::Vec2d CriminisiPriority::Normal(Pixel p) const {
  auto at = [&](int r, int c) {
    r = std::clamp(r, 0, blurred_hole_.rows - 1);
    c = std::clamp(c, 0, blurred_hole_.cols - 1);
    return static_cast<double>(blurred_hole_.at<float>(r, c));
  };
  const cv::Vec2d g(0.5 * (at(p.row + 1, p.col) - at(p.row - 1, p.col)),
                    0.5 * (at(p.row, p.col + 1) - at(p.row, p.col - 1)));
  const double n = std::hypot(g[0], g[1]);
  return n > 1e-12 ? g / n : cv::Vec2d(0.0, 0.0);
}

double CriminisiPriority::DataTerm(const InpaintCanvas& canvas, Pixel p) const {
  const int R = canvas.patch_radius();
  cv::Vec2d best(0.0, 0.0);
  double best_norm = -1.0;
  for (int r = std::max(0, p.row - R); r <= std::min(canvas.rows() - 1, p.row + R); ++r) {
    for (int c = std::max(0, p.col - R); c <= std::min(canvas.cols() - 1, p.col + R); ++c) {
      if (!canvas.IsKnown(r, c)) continue;
      const cv::Vec2d g = KnownGradient(canvas, {r, c}, options_.channel_weights);
      const double norm = g[0] * g[0] + g[1] * g[1];
      if (norm > best_norm) {
        best_norm = norm;
        best = g;
      }
    }
  }
  // Isophote = gradient rotated by 90°: (drow, dcol) -> (-dcol, drow).
  const cv::Vec2d isophote(-best[1], best[0]);
  const cv::Vec2d n = Normal(p);
  return std::abs(isophote.dot(n)) / options_.alpha + options_.data_floor;
}

double CriminisiPriority::Priority(const InpaintCanvas& canvas, Pixel p) const {
  return confidence_.Confidence(canvas, p) * DataTerm(canvas, p);
}

void CriminisiPriority::CheckConsistency(const InpaintCanvas& canvas) const {
  cv::Mat hole, fresh;
  cv::compare(canvas.known(), 0, hole, cv::CMP_EQ);
  hole.convertTo(hole, CV_32F, 1.0 / 255.0);
  if (cv::norm(hole, hole_, cv::NORM_INF) != 0.0)
    throw std::logic_error("CriminisiPriority: hole mask out of date");
  const int k = 2 * BlurRadius() + 1;
  cv::GaussianBlur(hole, fresh, cv::Size(k, k), options_.normal_sigma, options_.normal_sigma,
                   cv::BORDER_REPLICATE);
  const double error = cv::norm(fresh, blurred_hole_, cv::NORM_INF);
  if (error > 1e-5) {
    throw std::logic_error(
        fmt::format("CriminisiPriority: blurred mask differs from a full re-blur by {}", error));
  }
}

}  // namespace lidarshop
