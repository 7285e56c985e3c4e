#include "lidarshop/fill/fill.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include "lidarshop/fill/foreground.h"
#include "lidarshop/fill/range_gradient.h"
#include "lidarshop/fill/return_acceptance.h"
#include "lidarshop/inpaint/inpaint_session.h"
#include "lidarshop/inpaint/offset_completion.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/scan/lazy_zeros.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/scan/scan_window.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

using fill_internal::AbsQuantile;
using fill_internal::DepthJumps;
using fill_internal::EdgeMasks;
using fill_internal::GuidanceDivergence;
using fill_internal::NearestKnownCell;
using fill_internal::OneSidedRangeGradient;
using fill_internal::UnanchoredCells;

void FillOptions::Check() const { Validate(*this); }

InpaintOptions FillInpaintDefaults() {
  InpaintOptions inpaint;
  inpaint.patch_radius = 4;
  inpaint.search = InpaintSearchKind::kPatchMatch;
  inpaint.local_window_radius = 50;
  inpaint.acceptance = AcceptanceOptions::Combined();
  return inpaint;
}

std::string FillResult::Summary() const {
  return fmt::format(
      "filled {} hole cells: {} synthesized points, {} left without a return{}, {} patches{}; {:.2f} s "
      "(gradients "
      "{:.2f}, inpaint {:.2f}, lattice {:.2f}, poisson {:.2f}, planes {:.2f}, placement {:.2f})",
      hole_cells, synthesized_cells, no_return_cells,
      unanchored_cells ? fmt::format(" ({} cut off from every known range)", unanchored_cells) : "", patches,
      lattice_cells ? fmt::format(", {} cells copied along a facade's pitch", lattice_cells) : "",
      timings.total_s, timings.gradients_s, timings.inpaint_s, timings.lattice_s, timings.poisson_s,
      timings.planes_s, timings.placement_s);
}

cv::Mat GrowHole(const cv::Mat& hole, int margin_cells) {
  if (margin_cells < 0)
    throw OptionsError(fmt::format("the hole margin must be >= 0 cells, got {}", margin_cells));
  cv::Mat binary = hole != 0;
  if (margin_cells == 0) return binary;
  cv::Mat grown;
  const int size = 2 * margin_cells + 1;
  cv::dilate(binary, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(size, size)));
  return grown;
}

cv::Mat GrowHole(const cv::Mat& hole, int margin_cells, const cv::Rect& hole_box) {
  if (margin_cells < 0)
    throw OptionsError(fmt::format("the hole margin must be >= 0 cells, got {}", margin_cells));
  cv::Mat grown = LazyZeros(hole.rows, hole.cols, CV_8U);
  if (hole_box.empty()) return grown;  // no cell
  const cv::Rect box = cv::Rect(hole_box.x - margin_cells, hole_box.y - margin_cells,
                                hole_box.width + 2 * margin_cells, hole_box.height + 2 * margin_cells) &
                       cv::Rect(0, 0, hole.cols, hole.rows);
  if (!box.empty()) GrowHole(hole(box), margin_cells).copyTo(grown(box));
  return grown;
}

namespace {

// The front cells' least depth jump beyond 0.1 m, per metre of range (fill/foreground.h).
constexpr double kFrontJumpRatio = 0.03;

// What a method decides for the cells of the hole; the known cells keep the scan's values.
struct HoleValues {
  cv::Mat has_return;  // CV_8U 255 = the hole cell gets a return
  cv::Mat range;       // CV_32F, reconstructed range in the hole
  cv::Mat color;       // CV_8UC3 (scans with colour)
  cv::Mat intensity;   // CV_32F
  cv::Mat label;       // CV_32S (scans with labels)
  cv::Mat source;      // CV_32SC2 (row, col) the cell's attributes came from, patch methods
};

struct Inputs {
  const Scan* scan = nullptr;
  cv::Mat hole;         // CV_8U 255/0
  cv::Mat known_valid;  // CV_8U 255 = outside the hole with a return
  cv::Mat range;        // CV_32F, 0 where no return
  cv::Mat guide;        // CV_32FC(1 or 3): colour in grey levels, or intensity × 255
  cv::Mat front;        // CV_8U 255 = a known cell in front of the background (fill/foreground.h), or empty
};

cv::Mat Guide(const Scan& scan) {
  cv::Mat guide;
  if (scan.has_color()) {
    scan.color.convertTo(guide, CV_32FC3);
  } else if (!scan.intensity.empty()) {
    scan.intensity.convertTo(guide, CV_32F, 255.0);
  } else {
    guide = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(0));
  }
  // Cells without a return are black in the guide, whatever the file held there.
  guide.setTo(cv::Scalar::all(0), scan.valid == 0);
  return guide;
}

// Copies the attributes of each hole cell's source cell (patch methods); the row rule of range_gradient.h then
// takes the return from cells between two no-return regions of their row.
void CopyFromSources(const Inputs& in, const cv::Mat& source, HoleValues* out) {
  const Scan& scan = *in.scan;
  out->source = source;
  out->has_return = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  out->range = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(0));
  if (scan.has_color()) out->color = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));
  if (!scan.intensity.empty()) out->intensity = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(0.5));
  if (!scan.label.empty()) out->label = cv::Mat(scan.rows, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  for (int y = 0; y < scan.rows; ++y) {
    for (int x = 0; x < scan.cols; ++x) {
      if (!in.hole.at<uint8_t>(y, x)) continue;
      const cv::Vec2i s = source.at<cv::Vec2i>(y, x);
      if (s[0] < 0) continue;  // unreachable hole cell: stays without a return
      if (!scan.valid.at<uint8_t>(s[0], s[1])) continue;
      out->has_return.at<uint8_t>(y, x) = 255;
      out->range.at<float>(y, x) = in.range.at<float>(s[0], s[1]);
      if (!out->color.empty()) out->color.at<cv::Vec3b>(y, x) = scan.color.at<cv::Vec3b>(s[0], s[1]);
      if (!out->intensity.empty()) out->intensity.at<float>(y, x) = scan.intensity.at<float>(s[0], s[1]);
      if (!out->label.empty()) out->label.at<int32_t>(y, x) = scan.label.at<int32_t>(s[0], s[1]);
    }
  }
  out->has_return.setTo(0, fill_internal::NoReturnOnBothSides(in.hole, in.known_valid));
  // No return does not appear out of nothing: a part of the hole left without one that touches no known cell
  // without a return (sky, a dropout on the rim) is a copied no-return pattern — the stereo cloud's dropouts
  // copied as F-shaped holes into the table behind the mug — and gets a return, with the colour, intensity and
  // label of the nearest cell that has one.
  const cv::Mat without = (in.hole != 0) & (out->has_return == 0);
  cv::Mat ids;
  const int count = cv::connectedComponents(without, ids, 8, CV_32S);
  if (count > 1) {
    std::vector<uint8_t> open(static_cast<size_t>(count), 0);
    const cv::Mat known_without = (in.hole == 0) & (scan.valid == 0);
    for (int y = 0; y < scan.rows; ++y) {
      for (int x = 0; x < scan.cols; ++x) {
        const int id = ids.at<int32_t>(y, x);
        if (id == 0 || open[static_cast<size_t>(id)]) continue;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int yy = y + dy, xx = x + dx;
            const bool outside = yy < 0 || xx < 0 || yy >= scan.rows || xx >= scan.cols;
            if (outside || known_without.at<uint8_t>(yy, xx)) open[static_cast<size_t>(id)] = 1;
          }
      }
    }
    cv::Mat island(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
    for (int y = 0; y < scan.rows; ++y)
      for (int x = 0; x < scan.cols; ++x)
        if (const int id = ids.at<int32_t>(y, x); id > 0 && !open[static_cast<size_t>(id)])
          island.at<uint8_t>(y, x) = 255;
    const cv::Mat nearest = NearestKnownCell(island);
    for (int y = 0; y < scan.rows; ++y) {
      for (int x = 0; x < scan.cols; ++x) {
        if (!island.at<uint8_t>(y, x)) continue;
        const cv::Vec2i n = nearest.at<cv::Vec2i>(y, x);
        if (n[0] < 0) continue;
        const bool filled = in.hole.at<uint8_t>(n[0], n[1]) != 0;
        if (filled ? !out->has_return.at<uint8_t>(n[0], n[1]) : !scan.valid.at<uint8_t>(n[0], n[1])) continue;
        out->has_return.at<uint8_t>(y, x) = 255;
        if (!out->color.empty())
          out->color.at<cv::Vec3b>(y, x) =
              filled ? out->color.at<cv::Vec3b>(n[0], n[1]) : scan.color.at<cv::Vec3b>(n[0], n[1]);
        if (!out->intensity.empty())
          out->intensity.at<float>(y, x) =
              filled ? out->intensity.at<float>(n[0], n[1]) : scan.intensity.at<float>(n[0], n[1]);
        if (!out->label.empty())
          out->label.at<int32_t>(y, x) =
              filled ? out->label.at<int32_t>(n[0], n[1]) : scan.label.at<int32_t>(n[0], n[1]);
      }
    }
  }
}

// The joint image of the patch fill: the guide, `structure` channels (already scaled to grey levels), and the
// has-return channel; zero in the hole.
// The structure channels are taken (zeroed in the hole in place) and released once merged.
cv::Mat JointImage(const Inputs& in, std::vector<cv::Mat> structure) {
  std::vector<cv::Mat> planes;
  cv::split(in.guide, planes);
  for (cv::Mat& s : structure) planes.push_back(std::move(s));
  structure.clear();
  cv::Mat has_return;
  in.scan->valid.convertTo(has_return, CV_32F, 255.0 / 255.0);
  planes.push_back(has_return);
  for (cv::Mat& plane : planes)
    plane.setTo(0, in.hole);  // (cv::Scalar holds 4 channels, the joint image more)
  cv::Mat joint;
  cv::merge(planes, joint);
  return joint;
}

// 255 · asinh(v / scale) / asinh(1): linear near 0, logarithmic for large values, so that steep ground near
// the horizon and depth jumps keep their order without drowning the colour.
cv::Mat ScaledChannel(const cv::Mat& values, double scale) {
  cv::Mat scaled(values.size(), CV_32F);
  const double gain = 255.0 / std::asinh(1.0);
  for (int y = 0; y < values.rows; ++y) {
    const float* in = values.ptr<float>(y);
    float* out = scaled.ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) out[x] = static_cast<float>(gain * std::asinh(in[x] / scale));
  }
  return scaled;
}

InpaintResult PatchFill(const Inputs& in, std::vector<cv::Mat> structure, const FillOptions& options,
                        Progress* progress, FillResult* result_counts) {
  // The fill's inpainting as described (FillOptions::inpaint), with the search and the channel weights that
  // the fill decides.
  InpaintOptions inpaint = options.inpaint;
  // The exact search is the two-step one with the local window as its first bound: the same best patch,
  // found sooner.
  const double cost = static_cast<double>(result_counts->hole_cells) * static_cast<double>(in.hole.total());
  const bool exact =
      inpaint.search == InpaintSearchKind::kExhaustive ||
      (inpaint.search == InpaintSearchKind::kPatchMatch && cost <= options.exact_search_max_cost);
  if (exact) inpaint.search = InpaintSearchKind::kTwoStep;
  result_counts->exact_search = exact;
  inpaint.channel_weights.assign(static_cast<size_t>(in.guide.channels()),
                                 static_cast<float>(options.color_weight));
  for (size_t k = 0; k < structure.size(); ++k)
    inpaint.channel_weights.push_back(static_cast<float>(options.gradient_weight));
  inpaint.channel_weights.push_back(static_cast<float>(options.return_weight));
  cv::Mat joint = JointImage(in, std::move(structure));
  // The acceptance tests, and no sky brought into a patch whose known cells all returned
  // (fill/return_acceptance.h); the has-return channel is the joint image's last.
  const int has_return_channel = joint.channels() - 1;
  auto strategies = [&] {
    InpaintStrategies chosen;
    if (inpaint.acceptance.enabled) {
      chosen.acceptance = std::make_unique<fill_internal::ReturnConsistentAcceptance>(
          MakeAcceptance(inpaint.acceptance, inpaint.channel_weights), has_return_channel, in.front);
    }
    return chosen;
  };
  if (!options.offset_completion) {
    // Inpaint() without two copies of the window: the session holds the joint image (ours is released) and
    // the inpainted image is not made (the fill copies its channels from the sources).
    InpaintSession session(joint, in.hole, inpaint, strategies(), progress);
    joint.release();
    session.Run();
    return session.ResultWithoutImage();
  }

  OffsetCompletionOptions offsets = options.offsets;
  if (offsets.channel_weights.empty()) offsets.channel_weights = inpaint.channel_weights;
  const OffsetCompletionResult completed = CompleteByOffsets(joint, in.hole, offsets);
  result_counts->offset_cells = cv::countNonZero(completed.label >= 0);
  // What no offset could fill goes to the greedy fill, which may copy from the completed cells: its sources
  // are followed back to cells outside the hole.
  const cv::Mat rest = (in.hole != 0) & (completed.label < 0);
  cv::Mat image = joint.clone();
  const int channels = joint.channels();
  for (int y = 0; y < joint.rows; ++y) {
    for (int x = 0; x < joint.cols; ++x) {
      const cv::Vec2i s = completed.source_pixel.at<cv::Vec2i>(y, x);
      if (s[0] < 0) continue;
      std::copy_n(joint.ptr<float>(s[0]) + s[1] * channels, channels, image.ptr<float>(y) + x * channels);
    }
  }
  InpaintResult result;
  if (cv::countNonZero(rest) > 0) {
    result = Inpaint(image, rest, inpaint, strategies(), progress);
    for (auto it = result.source_pixel.begin<cv::Vec2i>(); it != result.source_pixel.end<cv::Vec2i>(); ++it) {
      if ((*it)[0] >= 0 && completed.source_pixel.at<cv::Vec2i>((*it)[0], (*it)[1])[0] >= 0)
        *it = completed.source_pixel.at<cv::Vec2i>((*it)[0], (*it)[1]);
    }
  } else {
    result.image = image;
    result.source_pixel = cv::Mat(joint.size(), CV_32SC2, cv::Scalar(-1, -1));
    result.fill_iteration = cv::Mat(joint.size(), CV_32S, cv::Scalar(-1));
  }
  completed.source_pixel.copyTo(result.source_pixel, completed.label >= 0);
  result.fill_iteration.setTo(0, completed.label >= 0);
  return result;
}

// Range in Ω = the hole cells with a return, from the Poisson equation with divergence
// `divergence` (empty = Laplace); returns the channels of `boundary` solved. Cells of Ω cut off
// from every known range lose their return.
cv::Mat SolveInHole(const Inputs& in, const FillOptions& options, HoleValues* values, const cv::Mat& boundary,
                    const cv::Mat& guidance_x, const cv::Mat& guidance_y, const EdgeMasks& cuts,
                    int64_t* unanchored) {
  cv::Mat domain = values->has_return.clone();
  const cv::Mat cut_off = UnanchoredCells(domain, in.known_valid, cuts);
  *unanchored = cv::countNonZero(cut_off);
  domain.setTo(0, cut_off);
  values->has_return.setTo(0, cut_off);
  const cv::Mat no_data = (in.known_valid | domain) == 0;
  if (cv::countNonZero(domain) == 0) return boundary.clone();
  const PoissonSystem system =
      PreparePoisson(domain, options.poisson, PoissonLinks{no_data, cuts.right, cuts.down});
  cv::Mat divergence;
  if (!guidance_x.empty()) divergence = GuidanceDivergence(guidance_x, guidance_y, no_data, cuts);
  return SolvePoisson(system, boundary, divergence).image;
}

void GradientFill(const Inputs& in, const FillOptions& options, Progress* progress, HoleValues* values,
                  FillResult* result) {
  Timer timer;
  // The field whose gradients are copied: the range, or its inverse, which is an affine function of the ray
  // direction on every plane (1/r = n·d / c for the plane n·p = c), so that its gradients change slowly
  // across a surface and a patch from a few rows away still fits.
  cv::Mat field = in.range.clone();
  if (options.inverse_range) {
    for (int y = 0; y < field.rows; ++y) {
      float* row = field.ptr<float>(y);
      for (int x = 0; x < field.cols; ++x) row[x] = row[x] > 0 ? 1.0f / row[x] : 0.0f;
    }
  }
  const auto gradient = OneSidedRangeGradient(field, in.known_valid);
  // Patches are matched on the range gradients (they tell a wall from the ground more sharply than those of
  // 1/r), and the gradients of `field` are copied. Only the scaled channels outlive this block: the patch
  // fill's peak holds no more than it needs (a window of a large station).
  std::vector<cv::Mat> structure;
  {
    const auto matched = options.inverse_range ? OneSidedRangeGradient(in.range, in.known_valid) : gradient;
    const double scale = std::max(AbsQuantile(matched.gx, in.known_valid, 0.9, 1e-9),
                                  AbsQuantile(matched.gy, in.known_valid, 0.9, 1e-9));
    structure.push_back(ScaledChannel(matched.gx, scale));
    structure.push_back(ScaledChannel(matched.gy, scale));
  }
  result->timings.gradients_s = timer.Seconds();

  timer.Restart();
  const InpaintResult patches = PatchFill(in, std::move(structure), options, progress, result);
  result->timings.inpaint_s = timer.Seconds();
  result->patches = patches.iterations;
  result->candidates_evaluated = patches.candidates_evaluated;
  result->fill_order = patches.fill_iteration;
  cv::Mat source = patches.source_pixel, relief_range;
  if (options.lattice.enabled) {
    timer.Restart();
    source = source.clone();
    const fill_internal::FacadeLatticeReport lattice = fill_internal::RefineSourcesByLattice(
        in.range, in.known_valid, in.scan->direction, in.guide, in.hole, GridOf(*in.scan), options.planes,
        options.lattice, options.inpaint.seed, &source, &relief_range);
    result->lattice_cells = lattice.cells;
    result->lattice_pitches_m = lattice.pitches_m;
    result->lattice_storeys_m = lattice.storeys_m;
    result->timings.lattice_s = timer.Seconds();
  }
  CopyFromSources(in, source, values);

  // The guidance field: known gradients outside, the copied ones inside; depth jumps are copied along and cut
  // the Poisson system there, so that surfaces at different distances are not joined by a membrane.
  cv::Mat gx = gradient.gx.clone(), gy = gradient.gy.clone();
  const EdgeMasks known_jumps = DepthJumps(in.range, in.known_valid, options.depth_jump_ratio);
  // Only edges leaving a hole cell can be in the system (known-to-known edges never are).
  EdgeMasks cuts{cv::Mat::zeros(in.hole.size(), CV_8U), cv::Mat::zeros(in.hole.size(), CV_8U)};
  for (int y = 0; y < in.hole.rows; ++y) {
    for (int x = 0; x < in.hole.cols; ++x) {
      if (!in.hole.at<uint8_t>(y, x)) continue;
      const cv::Vec2i s = source.at<cv::Vec2i>(y, x);
      if (s[0] < 0) continue;
      gx.at<float>(y, x) = gradient.gx.at<float>(s[0], s[1]);
      gy.at<float>(y, x) = gradient.gy.at<float>(s[0], s[1]);
      cuts.right.at<uint8_t>(y, x) = known_jumps.right.at<uint8_t>(s[0], s[1]);
      cuts.down.at<uint8_t>(y, x) = known_jumps.down.at<uint8_t>(s[0], s[1]);
    }
  }
  // Between two cells placed on a facade's lattice, the difference of their relief ranges (facade_lattice.h).
  if (!relief_range.empty()) {
    auto value = [&](int y, int x) {
      const float r = relief_range.at<float>(y, x);
      return options.inverse_range ? 1.0f / r : r;
    };
    for (int y = 0; y < in.hole.rows; ++y) {
      for (int x = 0; x < in.hole.cols; ++x) {
        if (!(relief_range.at<float>(y, x) > 0)) continue;
        if (x + 1 < in.hole.cols && relief_range.at<float>(y, x + 1) > 0) {
          gx.at<float>(y, x) = value(y, x + 1) - value(y, x);
          cuts.right.at<uint8_t>(y, x) = 0;
        }
        if (y + 1 < in.hole.rows && relief_range.at<float>(y + 1, x) > 0) {
          gy.at<float>(y, x) = value(y + 1, x) - value(y, x);
          cuts.down.at<uint8_t>(y, x) = 0;
        }
      }
    }
  }
  // Shifted copies meet at seams that no source edge describes (the greedy fill's patches overlap the cells
  // already filled, and its copies of one surface may come from different distances: no seam cuts there).
  if (options.offset_completion)
    fill_internal::SeamCuts(in.range, in.hole, source, options.depth_jump_ratio, &cuts);
  cv::magnitude(gradient.gx, gradient.gy, result->gradient_magnitude_before);
  result->gradient_magnitude_before.setTo(0, in.hole);
  cv::magnitude(gx, gy, result->gradient_magnitude_after);

  timer.Restart();
  cv::Mat boundary;
  field.convertTo(boundary, CV_64F);
  const cv::Mat solved = SolveInHole(in, options, values, boundary, gx, gy, cuts, &result->unanchored_cells);
  solved.convertTo(values->range, CV_32F);
  if (options.inverse_range) {
    // A non-positive inverse range would be a point behind the scanner or at infinity: no return.
    for (int y = 0; y < values->range.rows; ++y) {
      for (int x = 0; x < values->range.cols; ++x) {
        float& r = values->range.at<float>(y, x);
        r = r > 0 ? 1.0f / r : 0.0f;
      }
    }
  }
  result->timings.poisson_s = timer.Seconds();

  timer.Restart();
  result->plane_cells =
      fill_internal::SnapToPlanes(in.range, in.known_valid, in.scan->direction, in.hole, values->has_return,
                                  source, options.planes, options.inpaint.seed, &values->range);
  // The lattice's cells stand on their facade, refitted over a storey and several pitches of it, at their
  // source's relief: the planes of the band around the hole keep a tilt a narrow band cannot pin down, which a
  // source a pitch away would carry (a degree is 0.07 m at four metres). Only where the reconstruction agrees
  // (FillPlaneOptions::tolerance): a cell the patch fill gave the facade's colour at the foot of a wall standing
  // in front of it keeps the reconstruction's range.
  if (!relief_range.empty()) {
    for (int y = 0; y < relief_range.rows; ++y) {
      for (int x = 0; x < relief_range.cols; ++x) {
        const float lattice = relief_range.at<float>(y, x);
        float& r = values->range.at<float>(y, x);
        if (lattice > 0 && values->has_return.at<uint8_t>(y, x) &&
            std::abs(lattice - r) <= options.planes.tolerance * r)
          r = lattice;
      }
    }
  }
  result->timings.planes_s = timer.Seconds();
}

void DepthPatchFill(const Inputs& in, const FillOptions& options, Progress* progress, HoleValues* values,
                    FillResult* result) {
  Timer timer;
  // The range itself as the structure channel, scaled by its spread over the known cells.
  const double low = AbsQuantile(in.range, in.known_valid, 0.05, 0.0);
  const double high = AbsQuantile(in.range, in.known_valid, 0.95, low + 1e-3);
  cv::Mat shifted;
  in.range.convertTo(shifted, CV_32F, 1.0, -low);
  std::vector<cv::Mat> structure;
  structure.push_back(ScaledChannel(shifted, high - low));
  shifted.release();
  const InpaintResult patches = PatchFill(in, std::move(structure), options, progress, result);
  result->timings.inpaint_s = timer.Seconds();
  result->patches = patches.iterations;
  result->candidates_evaluated = patches.candidates_evaluated;
  result->fill_order = patches.fill_iteration;
  CopyFromSources(in, patches.source_pixel, values);  // copies the range as it is: the method under test
  result->unanchored_cells = 0;
}

// "Has a return" and the label from the nearest known cell (laplace and telea make no decision of their own).
void NearestKnownDecision(const Inputs& in, HoleValues* values) {
  const cv::Mat nearest = NearestKnownCell(in.hole);
  const Scan& scan = *in.scan;
  values->has_return = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  if (!scan.label.empty()) values->label = cv::Mat(scan.rows, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  for (int y = 0; y < scan.rows; ++y) {
    for (int x = 0; x < scan.cols; ++x) {
      const cv::Vec2i s = nearest.at<cv::Vec2i>(y, x);
      if (s[0] < 0 || !scan.valid.at<uint8_t>(s[0], s[1])) continue;
      values->has_return.at<uint8_t>(y, x) = 255;
      if (!values->label.empty()) values->label.at<int32_t>(y, x) = scan.label.at<int32_t>(s[0], s[1]);
    }
  }
}

void LaplaceFill(const Inputs& in, const FillOptions& options, HoleValues* values, FillResult* result) {
  const Scan& scan = *in.scan;
  NearestKnownDecision(in, values);
  Timer timer;
  // Range, intensity and colour in one solve.
  std::vector<cv::Mat> planes = {in.range};
  if (!scan.intensity.empty()) planes.push_back(scan.intensity);
  if (scan.has_color()) {
    cv::Mat color;
    scan.color.convertTo(color, CV_32FC3);
    std::vector<cv::Mat> rgb;
    cv::split(color, rgb);
    planes.insert(planes.end(), rgb.begin(), rgb.end());
  }
  cv::Mat boundary;
  cv::merge(planes, boundary);
  boundary.convertTo(boundary, CV_64F);
  const cv::Mat solved = SolveInHole(in, options, values, boundary, {}, {}, {}, &result->unanchored_cells);
  std::vector<cv::Mat> out;
  cv::split(solved, out);
  out[0].convertTo(values->range, CV_32F);
  int next = 1;
  if (!scan.intensity.empty()) out[next++].convertTo(values->intensity, CV_32F);
  if (scan.has_color()) {
    cv::Mat color;
    cv::merge(std::vector<cv::Mat>(out.begin() + next, out.begin() + next + 3), color);
    color.convertTo(values->color, CV_8UC3);  // rounds and saturates
  }
  result->timings.poisson_s = timer.Seconds();
}

void TeleaFill(const Inputs& in, const FillOptions& options, HoleValues* values, FillResult* result) {
  const Scan& scan = *in.scan;
  NearestKnownDecision(in, values);
  Timer timer;
  // Cells without a return near the hole are not sources either: mask them with the hole.
  const int reach = static_cast<int>(std::ceil(options.telea_radius_cells)) + 2;
  const cv::Mat near_hole = GrowHole(in.hole, reach);
  const cv::Mat mask = in.hole | (near_hole & (scan.valid == 0));
  // OpenCV's float path carries an absolute bias of about 0.1 per fill (measured: a constant 25.3 becomes
  // 25.40), so the range is inpainted on the 0..255 scale of its spread near the hole, then scaled back.
  double low = 0, high = 0;
  cv::minMaxLoc(in.range, &low, &high, nullptr, nullptr, near_hole & in.known_valid);
  const double span = std::max(high - low, 1e-3);
  cv::Mat scaled;
  in.range.convertTo(scaled, CV_32F, 255.0 / span, -low * 255.0 / span);
  cv::inpaint(scaled, mask, values->range, options.telea_radius_cells, cv::INPAINT_TELEA);
  values->range.convertTo(values->range, CV_32F, span / 255.0, low);
  if (!scan.intensity.empty())
    cv::inpaint(scan.intensity, mask, values->intensity, options.telea_radius_cells, cv::INPAINT_TELEA);
  if (scan.has_color())
    cv::inpaint(scan.color, mask, values->color, options.telea_radius_cells, cv::INPAINT_TELEA);
  result->timings.inpaint_s = timer.Seconds();
  result->unanchored_cells = 0;
}

void CheckInputs(const Scan& scan, const cv::Mat& hole) {
  if (hole.empty() || hole.rows != scan.rows || hole.cols != scan.cols) {
    throw InputError(
        fmt::format("the hole mask is {} x {} (cols x rows), the scan is {} x {}: they must match", hole.cols,
                    hole.rows, scan.cols, scan.rows));
  }
  if (hole.depth() != CV_8U || hole.channels() != 1) {
    throw InputError("the hole mask must be a single-channel 8-bit image (white = fill)");
  }
  if (!HasRayDirections(scan)) {
    throw InputError(
        "the scan has no ray directions (an unorganized cloud): only organized scans can be filled");
  }
}

// Normals of filled cells (scans with a normal channel): the grid normals of pointset/normals.h over a 3 x 3
// window, computed on the filled cells' bounding box only.
void GridNormals(const cv::Mat& filled, Scan* scan) {
  const cv::Rect box = cv::boundingRect(filled);
  if (box.empty()) return;
  NormalOptions options;
  options.window_cells = 1;
  const cv::Rect roi = (box + cv::Size(2, 2) - cv::Point(1, 1)) & cv::Rect(0, 0, scan->cols, scan->rows);
  Scan window;  // a view: the grid normals read rows, cols, valid and point only
  window.rows = roi.height;
  window.cols = roi.width;
  window.valid = scan->valid(roi);
  window.point = scan->point(roi);
  if (window.CountValid() < 3) return;
  const cv::Mat normal = EstimateGridNormals(window, options).normal;
  normal.copyTo(scan->normal(roi), filled(roi));
}

Scan PlaceAlongRays(const Inputs& in, const HoleValues& values, FillResult* result) {
  const Scan& scan = *in.scan;
  Scan out = Clone(scan);
  if (out.synthesized.empty()) out.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  result->filled = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  for (int y = 0; y < scan.rows; ++y) {
    for (int x = 0; x < scan.cols; ++x) {
      if (!in.hole.at<uint8_t>(y, x)) continue;
      const float range = values.range.empty() ? 0.0f : values.range.at<float>(y, x);
      const bool keep = values.has_return.at<uint8_t>(y, x) && std::isfinite(range) && range > 0.0f;
      out.valid.at<uint8_t>(y, x) = keep ? kValid : 0;
      out.range.at<float>(y, x) = keep ? range : 0.0f;
      const cv::Vec3f direction = scan.direction.at<cv::Vec3f>(y, x);
      out.point.at<cv::Vec3f>(y, x) = keep ? direction * range : cv::Vec3f(0, 0, 0);
      out.synthesized.at<uint8_t>(y, x) = keep ? kValid : 0;
      if (!out.intensity.empty()) {
        out.intensity.at<float>(y, x) = keep && !values.intensity.empty()
                                            ? std::clamp(values.intensity.at<float>(y, x), 0.0f, 1.0f)
                                            : 0.5f;
      }
      if (out.has_color()) {
        out.color.at<cv::Vec3b>(y, x) =
            keep && !values.color.empty() ? values.color.at<cv::Vec3b>(y, x) : cv::Vec3b(0, 0, 0);
      }
      if (!out.label.empty()) {
        out.label.at<int32_t>(y, x) =
            keep && !values.label.empty() ? values.label.at<int32_t>(y, x) : kNoLabel;
      }
      if (!out.true_range.empty()) out.true_range.at<float>(y, x) = 0.0f;  // no truth for a synthesized point
      if (!out.from_station.empty()) out.from_station.at<uint8_t>(y, x) = 0;  // invented here, not measured
      if (!out.normal.empty()) out.normal.at<cv::Vec3f>(y, x) = cv::Vec3f(0, 0, 0);
      if (!out.curvature.empty()) out.curvature.at<float>(y, x) = NAN;  // the filled surface's is unknown
      if (keep) {
        result->filled.at<uint8_t>(y, x) = 255;
        ++result->synthesized_cells;
      } else {
        ++result->no_return_cells;
      }
    }
  }
  if (!out.normal.empty()) GridNormals(result->filled, &out);
  return out;
}

}  // namespace

namespace {

// The window of FillOptions::window_margin: the hole's bounding box `box` grown, then doubled until it holds
// enough known returns (the whole scan at most). Only the windows tried are read.
cv::Rect FillWindow(const Scan& scan, const cv::Mat& hole, const cv::Rect& box, int64_t hole_cells,
                    const FillOptions& options) {
  const cv::Rect whole(0, 0, scan.cols, scan.rows);
  if (options.window_margin <= 0) return whole;
  int64_t margin = std::max<int64_t>(
      options.window_min_margin_cells,
      static_cast<int64_t>(std::ceil(options.window_margin * std::max(box.width, box.height))));
  while (true) {
    const int64_t x0 = std::max<int64_t>(0, box.x - margin), y0 = std::max<int64_t>(0, box.y - margin);
    const int64_t x1 = std::min<int64_t>(scan.cols, box.x + box.width + margin);
    const int64_t y1 = std::min<int64_t>(scan.rows, box.y + box.height + margin);
    const cv::Rect window(static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(x1 - x0),
                          static_cast<int>(y1 - y0));
    if (window == whole) return whole;
    const int64_t known = cv::countNonZero((scan.valid(window) != 0) & (hole(window) == 0));
    if (known >= options.window_min_known_ratio * hole_cells) return window;
    margin *= 2;
  }
}

// Throws InputError when a cell of the hole (inside `box`) has no ray direction.
void CheckHoleDirections(const Scan& scan, const cv::Mat& hole, const cv::Rect& box) {
  const RayDirections rays(scan);
  for (int y = box.y; y < box.y + box.height; ++y) {
    const uint8_t* in_hole = hole.ptr<uint8_t>(y);
    for (int x = box.x; x < box.x + box.width; ++x) {
      if (!in_hole[x]) continue;
      const cv::Vec3f d = rays(y, x);
      if (!(std::abs(d.dot(d) - 1.0f) < 1e-2f)) {
        throw InputError(fmt::format(
            "cell (row {}, col {}) of the hole has no ray direction: the scan's grid is unknown there", y,
            x));
      }
    }
  }
}

}  // namespace

void PadFillImages(int rows, int cols, FillResult* fill) {
  const cv::Rect window = fill->Window();
  auto pad = [&](cv::Mat* image, const cv::Scalar& outside) {
    if (image->rows == rows && image->cols == cols) return;
    cv::Mat full(rows, cols, image->empty() ? CV_8U : image->type(), outside);
    if (!image->empty()) image->copyTo(full(window));
    *image = full;
  };
  pad(&fill->filled, cv::Scalar(0));  // always: an empty hole's fill has filled nothing
  auto pad_debug = [&](cv::Mat* image, const cv::Scalar& outside) {
    if (!image->empty()) pad(image, outside);
  };
  pad_debug(&fill->gradient_magnitude_before, cv::Scalar(0));
  pad_debug(&fill->gradient_magnitude_after, cv::Scalar(0));
  pad_debug(&fill->fill_order, cv::Scalar(-1));
  pad_debug(&fill->source_cell, cv::Scalar(-1, -1));
}

void ApplyFill(const FillResult& fill, Scan* scan) {
  const cv::Rect window = fill.Window();
  if (window.area() == 0) return;
  PasteScan(fill.scan, window, scan);
}

void ExpandFill(const Scan& scan, FillResult* fill) {
  if (fill->Window() == cv::Rect(0, 0, scan.cols, scan.rows)) return;
  Scan whole = Clone(scan);
  ApplyFill(*fill, &whole);
  fill->scan = std::move(whole);
  PadFillImages(scan.rows, scan.cols, fill);
}

FillResult FillScan(const Scan& scan, const cv::Mat& hole, const FillOptions& options, Progress* progress) {
  Timer total;
  FillResult result = FillScanWindow(scan, hole, options, progress);
  ExpandFill(scan, &result);
  result.timings.total_s = total.Seconds();
  return result;
}

FillResult FillScanWindow(const Scan& scan, const cv::Mat& hole_in, const FillOptions& options,
                          Progress* progress) {
  options.Check();
  CheckInputs(scan, hole_in);
  Timer total;
  FillResult result;
  const cv::Rect hole_box = cv::boundingRect(hole_in);
  result.hole_cells = hole_box.empty() ? 0 : cv::countNonZero(hole_in(hole_box));
  if (result.hole_cells == 0) {
    result.warnings.push_back(
        "the hole mask is empty (no non-zero cell): nothing was filled, the output is a copy "
        "of the scan");
    result.timings.total_s = total.Seconds();
    return result;
  }
  const cv::Rect whole(0, 0, scan.cols, scan.rows);
  if (const cv::Rect window = FillWindow(scan, hole_in, hole_box, result.hole_cells, options);
      window != whole) {
    CheckHoleDirections(scan, hole_in, hole_box);
    FillOptions whole_window = options;
    whole_window.window_margin = 0;
    // The window is read in place (CropScanView): no copy of its cells.
    result = FillScanWindow(CropScanView(scan, window), hole_in(window), whole_window, progress);
    result.window_row = window.y;
    result.window_col = window.x;
    if (!result.source_cell.empty()) {
      result.source_cell.forEach<cv::Vec2i>([&](cv::Vec2i& source, const int*) {
        if (source[0] >= 0) source += cv::Vec2i(window.y, window.x);
      });
    }
    result.timings.total_s = total.Seconds();
    return result;
  }
  // The fill reads the window's rays as an image; a scan that holds none has its grid's (ray_directions.h).
  Scan with_rays = scan;
  with_rays.direction = DirectionImage(scan);
  Inputs in;
  in.scan = &with_rays;
  in.hole = hole_in != 0;
  in.known_valid = (scan.valid != 0) & (in.hole == 0);
  if (cv::countNonZero(in.known_valid) == 0) {
    throw InputError(
        "the hole mask leaves no known cell with a return: there is nothing to fill it from (the mask covers "
        "every return of the scan)");
  }
  CheckHoleDirections(scan, in.hole, hole_box);
  result.window_rows = scan.rows;
  result.window_cols = scan.cols;
  in.range = RangeImage(scan);
  in.range.setTo(0, scan.valid == 0);
  in.guide = Guide(scan);
  // The gradient fill continues the background only (fill/foreground.h): objects in front of it that touch the
  // hole are filled along with it (and not written), and no patch copies an object in front of it.
  const cv::Mat hole = in.hole.clone();
  bool extended = false;
  if (options.method == FillMethod::kGradient && options.background_only) {
    const cv::Rect box = cv::boundingRect(in.hole);
    const int reach = std::max(48, 2 * box.width);
    const cv::Mat front =
        fill_internal::FrontCells(in.range, in.known_valid, in.hole, kFrontJumpRatio, reach);
    // The removed object's own returns (the hole's cells that have one) give its range: a neighbour beside it
    // stands about as near (within the front jump of its farthest part).
    std::vector<float> object;
    for (int y = 0; y < scan.rows; ++y)
      for (int x = 0; x < scan.cols; ++x)
        if (in.hole.at<uint8_t>(y, x) && scan.valid.at<uint8_t>(y, x))
          object.push_back(in.range.at<float>(y, x));
    double max_range_m = std::numeric_limits<double>::infinity();
    if (!object.empty()) {
      const size_t far = object.size() * 9 / 10;
      std::nth_element(object.begin(), object.begin() + static_cast<std::ptrdiff_t>(far), object.end());
      max_range_m = object[far] * (1.0 + kFrontJumpRatio) + 0.1;
    }
    const cv::Mat touching =
        fill_internal::FrontTouchingHole(front, in.range, in.hole, in.known_valid, max_range_m, 2);
    if (cv::countNonZero(touching) > 0) {
      cv::bitwise_or(hole, touching, in.hole);
      extended = true;
      in.known_valid = (scan.valid != 0) & (in.hole == 0);
    }
    in.front = front & (in.hole == 0);
    result.front_cells = cv::countNonZero(touching);
  }

  HoleValues values;
  switch (options.method) {
    case FillMethod::kGradient:
      GradientFill(in, options, progress, &values, &result);
      break;
    case FillMethod::kDepthPatch:
      DepthPatchFill(in, options, progress, &values, &result);
      break;
    case FillMethod::kLaplace:
      LaplaceFill(in, options, &values, &result);
      break;
    case FillMethod::kTelea:
      TeleaFill(in, options, &values, &result);
      break;
  }
  // Back to the hole asked for: the front cells filled with it keep their own values.
  if (extended) {
    const cv::Mat extra = in.hole & (hole == 0);
    if (!values.source.empty()) values.source.setTo(cv::Scalar(-1, -1), extra);
    if (!result.fill_order.empty()) result.fill_order.setTo(-1, extra);
    if (!result.gradient_magnitude_after.empty()) {
      const cv::Mat known = (scan.valid != 0) & extra;
      result.gradient_magnitude_before.copyTo(result.gradient_magnitude_after, known);
    }
    in.hole = hole;
  }
  if (!values.source.empty()) result.source_cell = values.source;
  Timer timer;
  result.scan = PlaceAlongRays(in, values, &result);
  if (scan.direction.empty()) result.scan.direction.release();  // as it came: the rays are the grid's
  result.timings.placement_s = timer.Seconds();
  result.timings.total_s = total.Seconds();
  return result;
}

}  // namespace lidarshop
