#include "lidarshop/segment/segment_eval.h"

#include <algorithm>
#include <random>

#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {
namespace {

// A horizontal stroke of `length` centred on a random cell of `allowed`, clipped to `allowed`.
void DrawRandomStroke(const cv::Mat& allowed, std::mt19937_64* rng, int length, int width, uint8_t value,
                      cv::Mat* strokes) {
  std::vector<cv::Point> cells;
  cv::findNonZero(allowed, cells);
  if (cells.empty()) ThrowInputError("evaluation strokes", "", "", "no room for a stroke");
  const cv::Point c = cells[std::uniform_int_distribution<size_t>(0, cells.size() - 1)(*rng)];
  cv::Mat line(allowed.size(), CV_8U, cv::Scalar(0));
  cv::line(line, c - cv::Point(length / 2, 0), c + cv::Point(length / 2, 0), cv::Scalar(255), width);
  strokes->setTo(value, line & allowed);
}

}  // namespace

cv::Mat MakeEvalStrokes(const cv::Mat& truth, const cv::Mat& valid, uint64_t seed,
                        const EvalStrokeOptions& o) {
  LIDARSHOP_CHECK(truth.type() == CV_8U && valid.type() == CV_8U && truth.size() == valid.size());
  std::mt19937_64 rng(seed);
  cv::Mat object = (truth != 0) & (valid != 0), eroded;
  const int k = 2 * o.object_erosion_cells + 1;
  // Cells without a return count as outside the object, so the stroke stays clear of holes and edges.
  cv::erode(object, eroded, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)), cv::Point(-1, -1), 1,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  if (cv::countNonZero(eroded) == 0) eroded = object;  // thin objects: any object cell
  cv::Mat near_object;
  const int m = 2 * o.background_margin_cells + 1;
  cv::dilate(object, near_object, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(m, m)));
  const cv::Mat background = (valid != 0) & (near_object == 0);
  cv::Mat strokes(truth.size(), CV_8U, cv::Scalar(kStrokeNone));
  cv::Mat object_room = eroded, background_room = background;
  if (o.upper_and_below) {
    const cv::Rect inner = cv::boundingRect(eroded), outer = cv::boundingRect(object);
    object_room = eroded.clone();
    object_room.rowRange(inner.y + std::max(1, inner.height / 3), object_room.rows).setTo(0);
    const int below = outer.y + outer.height;  // the first row under the object
    cv::Mat under = background.clone();
    under.rowRange(0, below).setTo(0);
    cv::Mat under_columns = under.clone();
    under_columns.colRange(0, outer.x).setTo(0);
    under_columns.colRange(outer.x + outer.width, under.cols).setTo(0);
    if (cv::countNonZero(under_columns) > 0) {
      background_room = under_columns;
    } else if (cv::countNonZero(under) > 0) {
      background_room = under;
    }
  }
  DrawRandomStroke(object_room, &rng, o.stroke_length_cells, o.stroke_width_cells, kStrokeObject, &strokes);
  DrawRandomStroke(background_room, &rng, o.stroke_length_cells, o.stroke_width_cells, kStrokeBackground,
                   &strokes);
  return strokes;
}

std::vector<MethodScores> EvaluateMethods(const Scan& scan, const cv::Mat& truth, const cv::Mat& strokes,
                                          const SegmentOptions& options, int grabcut_iterations) {
  std::vector<MethodScores> out;
  for (SegmentMethod method :
       {SegmentMethod::kTwoStep, SegmentMethod::kDepth, SegmentMethod::kColor, SegmentMethod::kRgbd}) {
    SegmentOptions o = options;
    o.method = method;
    Timer timer;
    const SegmentResult result = SegmentObject(scan, strokes, o);
    const double seconds = timer.Seconds();
    out.push_back({ToString(method), ScoreMask(result.mask, truth, scan.valid), seconds});
    if (method == SegmentMethod::kTwoStep) {
      out.push_back({"step-1", ScoreMask(result.step1_mask, truth, scan.valid), seconds});
    }
  }
  if (grabcut_iterations > 0) {
    Timer timer;
    const cv::Mat mask = GrabCutFromStrokes(scan, strokes, grabcut_iterations);
    out.push_back({"grabcut", ScoreMask(mask, truth, scan.valid), timer.Seconds()});
  }
  return out;
}

namespace {

// A stroke of up to `length` cells of the largest 4-connected component of `part`, along its middle row,
// starting at the component's cell nearest its centroid. Returns false when `part` is empty.
bool StrokeOnLargestPart(const cv::Mat& part, uint8_t kind, int length, cv::Mat* strokes) {
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(part, labels, stats, centroids, 4, CV_32S);
  int largest = 0;
  for (int k = 1; k < count; ++k)
    if (largest == 0 || stats.at<int>(k, cv::CC_STAT_AREA) > stats.at<int>(largest, cv::CC_STAT_AREA))
      largest = k;
  if (largest == 0) return false;
  const int row = std::clamp(cvRound(centroids.at<double>(largest, 1)), 0, part.rows - 1);
  int start = -1;
  double best = 0;
  for (int col = 0; col < part.cols; ++col) {
    if (labels.at<int32_t>(row, col) != largest) continue;
    const double distance = std::abs(col - centroids.at<double>(largest, 0));
    if (start < 0 || distance < best) start = col, best = distance;
  }
  if (start < 0) {  // the middle row misses the component (a ring): its first cell
    std::vector<cv::Point> cells;
    cv::findNonZero(labels == largest, cells);
    strokes->at<uint8_t>(cells.front()) = kind;
    return true;
  }
  for (int col = start; col < std::min(part.cols, start + length) && labels.at<int32_t>(row, col) == largest;
       ++col)
    strokes->at<uint8_t>(row, col) = kind;
  return true;
}

// The object and the cells within 12 cells of it (the evaluation strokes' background margin).
cv::Mat AroundObject(const cv::Mat& object) {
  cv::Mat around;
  cv::dilate(object, around, cv::Mat(), cv::Point(-1, -1), EvalStrokeOptions().background_margin_cells);
  return around;
}

}  // namespace

RefinementScores EvaluateRefinement(const Scan& scan, const cv::Mat& truth, const cv::Mat& strokes,
                                    const SegmentOptions& options, int stroke_length_cells) {
  SegmentOptions o = options;
  o.method = SegmentMethod::kTwoStep;
  SegmentSession session(scan, o);
  const SegmentResult first = session.Run(strokes);
  RefinementScores out;
  out.before = ScoreMask(first.mask, truth, scan.valid);
  const cv::Mat valid = scan.valid != 0, object = truth != 0;
  cv::Mat extra(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  if (StrokeOnLargestPart(object & ~first.mask & valid, kStrokeObject, stroke_length_cells, &extra)) {
    out.stroke = "object";
  } else if (StrokeOnLargestPart(first.mask & ~object & valid, kStrokeBackground, stroke_length_cells,
                                 &extra)) {
    out.stroke = "background";
  } else if (StrokeOnLargestPart(valid & ~AroundObject(object), kStrokeBackground, stroke_length_cells,
                                 &extra)) {
    out.stroke = "background";  // nothing wrong: a correct stroke on the background away from the object
  } else {
    out.stroke = "none";
    out.after = out.before;
    return out;
  }
  out.after = ScoreMask(session.Refine(extra).mask, truth, scan.valid);
  return out;
}

MaskScores ScoreMask(const cv::Mat& mask, const cv::Mat& truth, const cv::Mat& domain) {
  LIDARSHOP_CHECK(mask.size() == truth.size() && mask.type() == CV_8U && truth.type() == CV_8U);
  LIDARSHOP_CHECK(domain.empty() || (domain.size() == mask.size() && domain.type() == CV_8U));
  MaskScores s;
  for (int row = 0; row < mask.rows; ++row) {
    const uint8_t* m = mask.ptr<uint8_t>(row);
    const uint8_t* t = truth.ptr<uint8_t>(row);
    const uint8_t* d = domain.empty() ? nullptr : domain.ptr<uint8_t>(row);
    for (int col = 0; col < mask.cols; ++col) {
      if (d != nullptr && d[col] == 0) continue;
      const bool a = m[col] != 0, b = t[col] != 0;
      s.true_positive += a && b;
      s.false_positive += a && !b;
      s.false_negative += !a && b;
    }
  }
  const double tp = double(s.true_positive);
  s.iou =
      tp + s.false_positive + s.false_negative > 0 ? tp / (tp + s.false_positive + s.false_negative) : 1.0;
  s.precision = tp + s.false_positive > 0 ? tp / (tp + s.false_positive) : 1.0;
  s.recall = tp + s.false_negative > 0 ? tp / (tp + s.false_negative) : 1.0;
  return s;
}

}  // namespace lidarshop
