// inpaint_eval: quality of the acceptance tests and of forward-looking filling
// (thesis ch. 7) on images with truth.
//
//   inpaint_eval [--scenes DIR] [--images DIR] [--configs a,b,...] [--lookahead M] [--markdown FILE]
//                [--pictures DIR] [--skip-trashcan] [--all-shared-images] [--colour-scenes]
//
// Configurations 0-11 are the library's (exhaustive search) with the acceptance tests one by one, combined
// and forward-looking; 12-25 are what `lidarshop inpaint` runs (two-step search, gain 1.5) with the flags a
// user can add (bench/results/inpaint.md, "The command's defaults"). The last table gives, per configuration,
// the mean, 5th percentile and worst PSNR over the images with truth and the seconds over the photos of
// --images.
//
// Images: lettera (its original is the truth), trashcan (no truth: its original still holds the object; time
// and rejections only) and, for every data/inpaint_eval/*.json scene, the synthetic scan rendered with and
// without the label-1 object (same seed; the truth is the scan without it). The hole is the object's cells
// dilated by 2 pixels. Synthetic scans are filled as one 5-channel image: colour (0..255) and the range's
// forward gradients (1 cm/pixel = 25 units), then the range is rebuilt in the hole by Poisson from the filled
// gradients (poisson/poisson.h) and compared with the true range (depth RMSE, metres).
// Per image and configuration: PSNR and SSIM of the grey values in the hole, rejected candidates, fallbacks,
// candidates per target and seconds.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/poisson/operators.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/scanner/scanner.h"

using namespace lidarshop;

namespace {

constexpr float kGradientScale = 2500.0f;  // units per metre of range difference between neighbours

struct EvalImage {
  std::string name;
  cv::Mat image;       // H x W CV_32FC(C): colour first (3 channels, 0..255)
  cv::Mat hole;        // CV_8U, 255 = hole
  cv::Mat truth_rgb;   // CV_8UC3, empty = no truth
  cv::Mat range;       // CV_32F range with the object (synthetic only)
  cv::Mat true_range;  // CV_32F range without it
};

cv::Mat Grey(const cv::Mat& rgb8) {
  cv::Mat grey;
  cv::cvtColor(rgb8, grey, cv::COLOR_RGB2GRAY);
  grey.convertTo(grey, CV_64F);
  return grey;
}

double HolePsnr(const cv::Mat& a, const cv::Mat& b, const cv::Mat& hole) {
  cv::Mat d = Grey(a) - Grey(b);
  const double mse = cv::mean(d.mul(d), hole)[0];
  return 10.0 * std::log10(255.0 * 255.0 / std::max(mse, 1e-12));
}

// Mean SSIM (Wang et al. 2004, Gaussian window σ = 1.5, K1 = 0.01, K2 = 0.03) over the hole's pixels.
double HoleSsim(const cv::Mat& a, const cv::Mat& b, const cv::Mat& hole) {
  const cv::Mat x = Grey(a), y = Grey(b);
  auto blur = [](const cv::Mat& m) {
    cv::Mat out;
    cv::GaussianBlur(m, out, cv::Size(11, 11), 1.5);
    return out;
  };
  const cv::Mat mx = blur(x), my = blur(y);
  const cv::Mat sxx = blur(x.mul(x)) - mx.mul(mx), syy = blur(y.mul(y)) - my.mul(my),
                sxy = blur(x.mul(y)) - mx.mul(my);
  const double c1 = 6.5025, c2 = 58.5225;
  cv::Mat num = (2 * mx.mul(my) + c1).mul(2 * sxy + c2);
  cv::Mat den = (mx.mul(mx) + my.mul(my) + c1).mul(sxx + syy + c2);
  cv::Mat ssim;
  cv::divide(num, den, ssim);
  return cv::mean(ssim, hole)[0];
}

cv::Mat ReadRgb(const std::string& path) {
  cv::Mat image = ReadImage(path);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_RGBA2RGB);
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2RGB);
  return image;
}

EvalImage SceneImage(const std::string& path) {
  SceneDescription scene = LoadScene(path);
  const Scan with = SynthesizeScan(scene);
  std::erase_if(scene.objects, [](const SceneObject& o) { return o.label == 1; });
  const Scan without = SynthesizeScan(scene);
  EvalImage e;
  e.name = std::filesystem::path(path).stem().string();
  cv::Mat object = with.label == 1;
  cv::dilate(object, e.hole, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  e.truth_rgb = without.color.clone();
  e.range = with.range.clone();
  e.true_range = without.range.clone();
  const ImageGradient g = ForwardGradient(with.range);
  cv::Mat colour;
  with.color.convertTo(colour, CV_32F);
  std::vector<cv::Mat> channels;
  cv::split(colour, channels);
  channels.push_back(g.gx * kGradientScale);
  channels.push_back(g.gy * kGradientScale);
  cv::merge(channels, e.image);
  return e;
}

struct Config {
  std::string name;
  InpaintOptions options;
};

// Overrides of the combined configurations (for tuning; negative = keep).
struct Tuning {
  int band_px = -1, candidates = -1, window = -1;
  double representative = -1, histogram = -1, smooth = -1;
};

std::vector<Config> MakeConfigs(int lookahead, const Tuning& t) {
  std::vector<Config> configs;
  InpaintOptions plain;
  plain.search = InpaintSearchKind::kExhaustive;
  configs.push_back({"plain Criminisi (exhaustive)", plain});
  auto alone = [&](const std::string& name, auto enable) {
    InpaintOptions o = plain;
    o.acceptance.enabled = true;
    o.acceptance.band_px = 2;
    enable(o.acceptance);
    configs.push_back({name, o});
  };
  alone("mean", [](AcceptanceOptions& a) { a.mean.enabled = true; });
  alone("representative", [](AcceptanceOptions& a) { a.representative.enabled = true; });
  alone("histogram (full, EMD)", [](AcceptanceOptions& a) { a.histogram.enabled = true; });
  alone("histogram (full, intersection)", [](AcceptanceOptions& a) {
    a.histogram.enabled = true;
    a.histogram.metric = HistogramMetric::kIntersection;
    a.histogram.max_distance = 0.5;
  });
  alone("histogram (compressed, EMD)", [](AcceptanceOptions& a) {
    a.histogram.enabled = true;
    a.histogram.range = HistogramRange::kCompressed;
  });
  alone("histogram (halves, EMD)", [](AcceptanceOptions& a) {
    a.histogram.enabled = true;
    a.histogram.quadrants = true;
  });
  alone("smooth vs textured", [](AcceptanceOptions& a) { a.smooth_texture.enabled = true; });
  InpaintOptions combined = plain;
  combined.acceptance = AcceptanceOptions::Combined();
  if (t.band_px >= 0) combined.acceptance.band_px = t.band_px;
  if (t.candidates > 0) combined.acceptance_candidates = t.candidates;
  if (t.window > 0) combined.local_window_radius = t.window;
  if (t.representative > 0) combined.acceptance.representative.max_difference = t.representative;
  if (t.histogram > 0) combined.acceptance.histogram.max_distance = t.histogram;
  if (t.smooth > 0) combined.acceptance.smooth_texture.max_value = t.smooth;
  configs.push_back({"combined", combined});
  combined.acceptance_local_first = false;
  configs.push_back({"combined, whole image first", combined});
  combined.acceptance_local_first = true;
  combined.lookahead = lookahead;
  configs.push_back({fmt::format("combined + lookahead {} (largest margin)", lookahead), combined});
  combined.lookahead_by_margin = false;
  configs.push_back({fmt::format("combined + lookahead {} (first passing)", lookahead), combined});
  // 12-: the `lidarshop inpaint` command's settings (two-step search, gain 1.5; cli/inpaint_command.cc) with
  // the flags a user would add; 12 is the command's default before #30, 14 its default since.
  InpaintOptions command;
  command.search = InpaintSearchKind::kTwoStep;
  command.global_gain = 1.5;
  configs.push_back({"command: --accept none --lookahead 1 (two-step 1.5)", command});
  command.acceptance = AcceptanceOptions::Combined();
  configs.push_back({"command: --accept combined", command});
  for (int m : {2, 4, 8}) {
    command.lookahead = m;
    configs.push_back({fmt::format("command: --accept combined --lookahead {}", m), command});
  }
  command.lookahead = 4;
  command.lookahead_by_margin = false;
  configs.push_back({"command: --accept combined --lookahead 4 --lookahead-by-margin false", command});
  command.lookahead_by_margin = true;
  command.acceptance_candidates = 16;
  configs.push_back({"command: --accept combined --lookahead 4 --accept-candidates 16", command});
  command.acceptance_candidates = 8;
  command.search = InpaintSearchKind::kExhaustive;
  configs.push_back({"command: --accept combined --lookahead 4 --search exhaustive", command});
  command.search = InpaintSearchKind::kPatchMatch;
  configs.push_back({"command: --accept combined --lookahead 4 --search patchmatch", command});
  // Lookahead 1 with the acceptance's own knobs.
  command.search = InpaintSearchKind::kTwoStep;
  command.lookahead = 1;
  for (int k : {4, 16}) {
    command.acceptance_candidates = k;
    configs.push_back({fmt::format("command: --accept combined --accept-candidates {}", k), command});
  }
  command.acceptance_candidates = 8;
  command.local_window_radius = 20;
  configs.push_back({"command: --accept combined --window 20", command});
  command.local_window_radius = 40;
  command.acceptance.band_px = 1;
  configs.push_back({"command: --accept combined --accept-band 1", command});
  command.acceptance.band_px = AcceptanceOptions::Combined().band_px;
  command.global_gain = 1.0;
  configs.push_back({"command: --accept combined --global-gain 1", command});
  return configs;
}

cv::Mat ColourOf(const cv::Mat& filled) {
  cv::Mat colour, out;
  std::vector<cv::Mat> c(3);
  for (int k = 0; k < 3; ++k) cv::extractChannel(filled, c[k], k);
  cv::merge(c, colour);
  colour.convertTo(out, CV_8U);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Inpainting quality of the acceptance tests and forward-looking filling on images with truth"};
  std::string scenes_dir = LIDARSHOP_SOURCE_DIR "/data/inpaint_eval",
              images_dir = LIDARSHOP_SHARED_DATA_DIR "/images", markdown_path, pictures_dir, only;
  int lookahead = 8;
  bool skip_trashcan = false, all_shared = false, colour_scenes = false;
  app.add_option("--scenes", scenes_dir, "folder of scene JSON files (label 1 = the object to remove)");
  app.add_option("--images", images_dir, "folder with lettera/ and trashcan/");
  app.add_option("--lookahead", lookahead, "M of the forward-looking configuration")->capture_default_str();
  app.add_option("--configs", only, "comma-separated indices of the configurations to run (default all)");
  app.add_option("--markdown", markdown_path, "also write the tables to this file");
  app.add_option("--pictures", pictures_dir,
                 "write the input, plain and combined fills (and the truth) here, cropped around the hole");
  app.add_flag("--skip-trashcan", skip_trashcan);
  app.add_flag(
      "--all-shared-images", all_shared,
      "also fill bungee and f16 of --images (no truth: time only), for the summary's shared-image time");
  app.add_flag("--colour-scenes", colour_scenes,
               "also fill each scene's colour alone (3 channels, as `lidarshop inpaint` fills a photo)");
  Tuning tuning;
  app.add_option("--band", tuning.band_px, "combined: band_px");
  app.add_option("--candidates", tuning.candidates, "combined: acceptance_candidates");
  app.add_option("--window", tuning.window, "combined: local_window_radius");
  app.add_option("--representative", tuning.representative, "combined: representative.max_difference");
  app.add_option("--histogram", tuning.histogram, "combined: histogram.max_distance");
  app.add_option("--smooth", tuning.smooth, "combined: smooth_texture.max_value");
  CLI11_PARSE(app, argc, argv);

  std::vector<EvalImage> images;
  {
    EvalImage l;
    l.name = "lettera";
    ReadRgb(images_dir + "/lettera/lettera.png").convertTo(l.image, CV_32F);
    l.hole = ReadImage(images_dir + "/lettera/lettera_mask.png") > 127;
    l.truth_rgb = ReadRgb(images_dir + "/lettera/lettera_original.png");
    images.push_back(l);
  }
  std::vector<std::string> scene_paths;
  for (const auto& entry : std::filesystem::directory_iterator(scenes_dir))
    if (entry.path().extension() == ".json") scene_paths.push_back(entry.path().string());
  std::sort(scene_paths.begin(), scene_paths.end());
  for (const std::string& path : scene_paths) images.push_back(SceneImage(path));
  if (colour_scenes) {
    for (const std::string& path : scene_paths) {
      EvalImage e = SceneImage(path);
      e.name += " (colour only)";
      e.image = ColourOf(e.image);
      e.image.convertTo(e.image, CV_32F);
      e.range.release();
      e.true_range.release();
      images.push_back(e);
    }
  }
  if (!skip_trashcan) {
    EvalImage t;
    t.name = "trashcan";
    ReadRgb(images_dir + "/trashcan/trashcan.png").convertTo(t.image, CV_32F);
    t.hole = ReadImage(images_dir + "/trashcan/trashcan_mask.png") > 127;
    images.push_back(t);
  }
  if (all_shared) {
    for (const auto& [name, stem] : {std::pair{"bungee", "bungee"}, std::pair{"f16", "f16"}}) {
      EvalImage e;
      e.name = name;
      ReadRgb(fmt::format("{}/{}/{}.png", images_dir, name, stem)).convertTo(e.image, CV_32F);
      cv::Mat mask = ReadImage(fmt::format("{}/{}/{}_mask.png", images_dir, name, stem));
      if (mask.channels() == 3) cv::cvtColor(mask, mask, cv::COLOR_RGB2GRAY);
      if (mask.channels() == 4) cv::cvtColor(mask, mask, cv::COLOR_RGBA2GRAY);
      e.hole = mask > 127;
      images.push_back(e);
    }
  }
  std::vector<Config> configs = MakeConfigs(lookahead, tuning);
  std::vector<bool> run(configs.size(), only.empty());
  std::stringstream list(only);
  for (std::string item; std::getline(list, item, ',');) run.at(std::stoi(item)) = true;

  std::string out;
  auto emit = [&](const std::string& s) {
    fmt::print("{}", s);
    std::fflush(stdout);
    out += s;
  };
  // Per configuration: PSNR of every image with truth, seconds over the images of --images (lettera,
  // trashcan, bungee, f16: the shared photos, not the synthetic scans).
  std::vector<std::vector<double>> psnrs(configs.size());
  std::vector<double> shared_seconds(configs.size(), 0.0);
  for (const EvalImage& e : images) {
    const bool shared = e.image.channels() == 3 && e.name.find("(colour only)") == std::string::npos;
    const int hole = cv::countNonZero(e.hole);
    emit(fmt::format("\n### {} ({}x{}, {} channels, hole {} px)\n\n", e.name, e.image.cols, e.image.rows,
                     e.image.channels(), hole));
    emit(
        "| configuration | PSNR dB | SSIM | depth RMSE m | rejected | fallbacks | targets | candidates / "
        "target "
        "| s |\n|---|---|---|---|---|---|---|---|---|\n");
    for (size_t i = 0; i < configs.size(); ++i) {
      if (!run[i]) continue;
      InpaintOptions options = configs[i].options;
      if (e.image.channels() == 5) options.channel_weights = {1, 1, 1, 1, 1};
      const InpaintResult result = Inpaint(e.image, e.hole, options);
      const cv::Mat rgb = ColourOf(result.image);
      std::string psnr = "-", ssim = "-", rmse = "-";
      if (!e.truth_rgb.empty()) {
        psnrs[i].push_back(HolePsnr(rgb, e.truth_rgb, e.hole));
        psnr = fmt::format("{:.2f}", psnrs[i].back());
        ssim = fmt::format("{:.3f}", HoleSsim(rgb, e.truth_rgb, e.hole));
      }
      if (!e.range.empty()) {
        cv::Mat gx, gy;
        cv::extractChannel(result.image, gx, 3);
        cv::extractChannel(result.image, gy, 4);
        const PoissonSystem system = PreparePoisson(e.hole);
        const PoissonResult depth =
            ReconstructFromGradients(system, e.range, gx / kGradientScale, gy / kGradientScale);
        cv::Mat d = depth.image - e.true_range;
        rmse = fmt::format("{:.4f}", std::sqrt(cv::mean(d.mul(d), e.hole)[0]));
      }
      if (shared) shared_seconds[i] += result.seconds;
      emit(fmt::format("| {} | {} | {} | {} | {} | {} | {} | {:.0f} | {:.2f} |\n", configs[i].name, psnr,
                       ssim, rmse, result.rejected, result.acceptance_fallbacks, result.iterations,
                       static_cast<double>(result.candidates_evaluated) / std::max(result.iterations, 1),
                       result.seconds));
      if (!pictures_dir.empty() && (i == 0 || i == 8)) {
        // The hole's bounding box with a 24-pixel margin.
        const cv::Rect box = (cv::boundingRect(e.hole) + cv::Size(48, 48) - cv::Point(24, 24)) &
                             cv::Rect(0, 0, e.hole.cols, e.hole.rows);
        std::filesystem::create_directories(pictures_dir);
        auto write = [&](const std::string& what, const cv::Mat& picture) {
          WriteImage(fmt::format("{}/{}_{}.png", pictures_dir, e.name, what), picture(box));
        };
        write(i == 0 ? "plain" : "combined", rgb);
        if (i == 0) {
          cv::Mat input = ColourOf(e.image);
          input.setTo(cv::Scalar(255, 0, 255), e.hole);
          write("input", input);
          if (!e.truth_rgb.empty() && e.image.channels() == 5) write("truth", e.truth_rgb);
        }
      }
    }
  }
  // The distribution over the images with truth: mean, 5th percentile (nearest rank, the lowest of fewer than
  // 20 images) and worst.
  emit(
      "\n### Summary over the images with truth\n\n| configuration | PSNR mean dB | 5th percentile | worst | "
      "s on the shared photos |\n|---|---|---|---|---|\n");
  for (size_t i = 0; i < configs.size(); ++i) {
    if (!run[i] || psnrs[i].empty()) continue;
    std::vector<double> v = psnrs[i];
    std::sort(v.begin(), v.end());
    double mean = 0;
    for (double x : v) mean += x / v.size();
    const size_t p5 = static_cast<size_t>(std::ceil(0.05 * v.size())) - 1;
    emit(fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} |\n", configs[i].name, mean,
                     v[std::min(p5, v.size() - 1)], v.front(), shared_seconds[i]));
  }
  if (!markdown_path.empty()) {
    std::ofstream file(markdown_path);
    file << out;
  }
  return 0;
}
