// lidarshop inpaint: greedy patch-based inpainting of an image (inpaint/inpaint.h, docs/inpaint.md).
#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/inpaint_review.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/inpaint/debug_images.h"
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/progress.h"

namespace lidarshop::cli {

namespace {

// --accept LIST into options.acceptance, keeping --accept-band (when > 0) and --histogram-metric.
void ParseAcceptance(const std::string& list, InpaintOptions* options) {
  AcceptanceOptions& a = options->acceptance;
  const int band = a.band_px;
  const HistogramMetric metric = a.histogram.metric;
  std::stringstream stream(list);
  std::string name;
  while (std::getline(stream, name, ',')) {
    if (name == "none") continue;
    a.enabled = true;
    if (name == "combined") {
      a = AcceptanceOptions::Combined();
    } else if (name == "mean") {
      a.mean.enabled = true;
    } else if (name == "representative") {
      a.representative.enabled = true;
    } else if (name == "histogram" || name == "histogram-compressed" || name == "histogram-quadrants") {
      a.histogram.enabled = true;
      if (name == "histogram-compressed") a.histogram.range = HistogramRange::kCompressed;
      if (name == "histogram-quadrants") a.histogram.quadrants = true;
    } else if (name == "smooth-texture") {
      a.smooth_texture.enabled = true;
    } else {
      throw OptionsError(fmt::format("--accept: unknown test '{}'", name));
    }
  }
  if (band > 0) a.band_px = band;
  a.histogram.metric = metric;
}

// 8-bit display of a filled float image in the input's depth (16-bit and float are stretched to 0..255).
void ToDisplay(const cv::Mat& image, int depth, cv::Mat* display) {
  if (depth == CV_8U) {
    image.convertTo(*display, CV_8U);
  } else {
    cv::normalize(image, *display, 0, 255, cv::NORM_MINMAX, CV_8U);
  }
}

}  // namespace

int RunInpaint(int argc, char** argv) {
  CLI::App app{
      "Fill the hole of an image with patches copied from the rest of it (Criminisi et al. 2004 and "
      "variants; "
      "docs/inpaint.md). MASK: white (> 127) = hole, same size as IMAGE. 8-bit and 16-bit images come back "
      "in "
      "their depth; float images (EXR, TIFF) stay float.",
      "inpaint"};
  std::string image_path, mask_path, output_path, debug_dir;
  InpaintOptions options;
  // The command's default search is two-step with gain 1.5: it continues structure best (lettera: 40 dB in
  // the hole vs 20 dB for the exhaustive search, bench/results/inpaint.md). `--search exhaustive` is plain
  // Criminisi (the paper's setup, and the library's default). Without acceptance and lookahead 1: of 14 settings
  // a user can pick, these have the best mean PSNR on inpaint_eval's 9 images with truth (issue #30;
  // `--accept combined` is 0.4 dB lower and 8x faster; bench/results/inpaint.md, "The command's defaults").
  options.search = InpaintSearchKind::kTwoStep;
  options.global_gain = 1.5;
  bool quiet = false;
  std::string accept = "none", review_dir, resume_dir, place, json_path;
  int choose = -1;
  OptionBinder binder(app);
  app.add_option("image", image_path, "image to fill (.png, .jpg, .exr, .tif)")->required();
  app.add_option("--mask", mask_path, "hole mask (white = hole)")->required();
  app.add_option("-o,--output", output_path, "filled image (.png/.jpg for 8/16-bit, .exr/.tif for float)")
      ->required();
  AddJsonOption(app, &json_path);
  // alpha follows the image's depth, stop_for_review --review; check_bookkeeping is for tests.
  binder.Bind(&options, {.skip = {"alpha", "stop_for_review", "check_bookkeeping"},
                         .flags = {{"priority", "--method"},
                                   {"local_window_radius", "--window"},
                                   {"acceptance_candidates", "--accept-candidates"}}});
  binder.Bind(&options, {.keys = {"acceptance.band_px", "acceptance.histogram.metric"},
                         .flags = {{"acceptance.band_px", "--accept-band"},
                                   {"acceptance.histogram.metric", "--histogram-metric"}}});
  app.add_option("--debug", debug_dir,
                 "write fill_order.png, source_map.png, source_locations.png and steps.csv into this folder");
  app.add_option("--accept", accept,
                 "acceptance tests, comma-separated, ANDed: combined (= "
                 "representative,histogram-quadrants,smooth-texture "
                 "on a 2-px band) | none | mean | representative | histogram | histogram-compressed | "
                 "histogram-quadrants | smooth-texture")
      ->capture_default_str();
  app.add_option("--review", review_dir,
                 "stop where no candidate passes and write the review (review.json, tentative.png, "
                 "clusters.png) into this folder");
  app.add_option("--resume", resume_dir,
                 "continue the fill reviewed in this folder (with --choose or --place)");
  app.add_option("--choose", choose, "with --resume: copy candidate N of review.json");
  app.add_option("--place", place, "with --resume: copy the source patch centred at ROW,COL instead");
  AddQuietFlag(app, &quiet);
  return RunCommand(
      app, argc, argv,
      [&]() {
        ParseAcceptance(accept, &options);
        binder.Validate(options);
        CheckOutputPath(output_path, {image_path, mask_path});
        CheckOutputFile("--json", json_path, {}, {image_path, mask_path, output_path});
        if (!resume_dir.empty()) {
          if ((choose >= 0) == !place.empty())
            throw OptionsError("--resume needs exactly one of --choose N and --place ROW,COL");
          const ReviewFolder folder = ReadReviewFolder(resume_dir);
          options.review_decisions = folder.decisions;
          Pixel source;
          if (choose >= 0) {
            if (choose >= static_cast<int>(folder.candidates.size()))
              throw OptionsError(fmt::format("--choose {}: the review lists {} candidates", choose,
                                             folder.candidates.size()));
            source = folder.candidates[choose];
          } else if (std::sscanf(place.c_str(), "%d,%d", &source.row, &source.col) != 2) {
            throw OptionsError(fmt::format("--place must be ROW,COL, got '{}'", place));
          }
          options.review_decisions.push_back({folder.target, source});
          if (review_dir.empty()) review_dir = resume_dir;
        } else if (choose >= 0 || !place.empty()) {
          throw OptionsError("--choose and --place need --resume DIR");
        }
        options.stop_for_review = !review_dir.empty();
        const cv::Mat input = ReadImage(image_path);
        cv::Mat mask = ReadImage(mask_path, input.size(), "the image");  // size checked before decoding
        if (mask.channels() == 3) cv::cvtColor(mask, mask, cv::COLOR_RGB2GRAY);
        if (mask.channels() == 4) cv::cvtColor(mask, mask, cv::COLOR_RGBA2GRAY);
        if (mask.depth() != CV_8U) ThrowInputError(mask_path, "", "", "the mask must be an 8-bit image");
        mask = mask > 127;
        std::string extension = std::filesystem::path(output_path).extension().string();
        std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
        if ((input.depth() == CV_32F || input.depth() == CV_64F) &&
            (extension == ".png" || extension == ".jpg" || extension == ".jpeg")) {
          ThrowInputError(output_path, "", "", "a float image must be written as .exr or .tif");
        }
        cv::Mat image;
        input.convertTo(image, CV_32F);
        // Data-term scale: the intensity range (255 for 8-bit images).
        if (input.depth() == CV_8U) {
          options.alpha = 255.0;
        } else {
          double low = 0.0, high = 0.0;
          cv::minMaxLoc(image.reshape(1), &low, &high);
          options.alpha = std::max(high - low, 1e-6);
        }
        auto progress = Progress::ForTerminal("inpaint", cv::countNonZero(mask), quiet);
        const InpaintResult result = Inpaint(image, mask, options, progress.get());
        if (!result.complete) {
          cv::Mat tentative, canvas;
          ToDisplay(result.review->tentative_image, input.depth(), &tentative);
          ToDisplay(result.image, input.depth(), &canvas);
          WriteReviewFolder(review_dir, *result.review, options.review_decisions, tentative, canvas,
                            options.patch_radius);
          fmt::print(
              stderr,
              "stopped for review at iteration {} (target row {}, col {}): {} candidates in {} clusters, "
              "see {}/review.json; continue with --resume {} --choose N\n",
              result.review->iteration, result.review->target.row, result.review->target.col,
              result.review->candidates.size(), result.review->cluster_representative.size(), review_dir,
              review_dir);
          WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(result)));
          return 0;
        }
        cv::Mat output;
        result.image.convertTo(output, input.depth());
        WriteImage(output_path, output);
        if (!debug_dir.empty()) {
          std::filesystem::create_directories(debug_dir);
          cv::Mat background = result.image;
          if (input.depth() != CV_8U) cv::normalize(result.image, background, 0, 255, cv::NORM_MINMAX);
          const std::string dir = debug_dir + "/";
          WriteImage(dir + "fill_order.png", RenderFillOrder(result, background));
          WriteImage(dir + "source_map.png", RenderSourceMap(result, background));
          InpaintResult scaled;
          scaled.image = background;
          scaled.steps = result.steps;
          WriteImage(dir + "source_locations.png", RenderSourceLocations(scaled, options.patch_radius));
          WriteFileAtomically(dir + "steps.csv", [&](std::ostream& out) {
            out << "iteration,target_row,target_col,source_row,source_col,difference,priority,filled_pixels,"
                   "rejected,accepted,margin\n";
            for (size_t i = 0; i < result.steps.size(); ++i) {
              const FillStep& s = result.steps[i];
              out << fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", i, s.target.row, s.target.col,
                                 s.source.row, s.source.col, s.difference, s.priority, s.filled_pixels,
                                 s.rejected, s.accepted ? 1 : 0, s.margin);
            }
          });
        }
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(result)));
        Summarize(result.Summary());
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
