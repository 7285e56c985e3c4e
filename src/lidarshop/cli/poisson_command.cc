// lidarshop poisson: Poisson image editing on a masked domain (poisson/poisson.h, docs/poisson.md).
//
//   lidarshop poisson fill IMAGE --mask MASK -o OUT.png
//   lidarshop poisson clone SOURCE --mask MASK --target TARGET --offset X,Y -o OUT.png
//   lidarshop poisson reconstruct --gx GX.exr --gy GY.exr --boundary IMAGE --mask MASK -o OUT.exr
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/text.h"

namespace lidarshop::cli {
namespace {

cv::Mat ReadFloat(const std::string& path) {
  const cv::Mat image = ReadImage(path);
  cv::Mat result;
  image.convertTo(result, CV_32F);
  return result;
}

// Float results go to .exr / .tif(f) as 32-bit; other formats get `integer_depth` (8- or
// 16-bit, rounded and saturated).
void WriteResult(const std::string& path, const cv::Mat& image, int integer_depth) {
  const std::string lower = AsciiLower(path);
  const bool float_format = lower.ends_with(".exr") || lower.ends_with(".tif") || lower.ends_with(".tiff");
  cv::Mat output;
  image.convertTo(output, float_format ? CV_32F : integer_depth);
  WriteImage(path, output);
}

int IntegerDepth(const cv::Mat& image) { return image.depth() == CV_16U ? CV_16U : CV_8U; }

cv::Point ParseOffset(const std::string& text) {
  int x = 0, y = 0;
  char comma = 0;
  std::istringstream stream(text);
  if (!(stream >> x >> comma >> y) || comma != ',' || !stream.eof()) {
    throw OptionsError(fmt::format("--offset must be X,Y in pixels (e.g. 110,-20), got '{}'", text));
  }
  return {x, y};
}

}  // namespace

int RunPoisson(int argc, char** argv) {
  CLI::App app{
      "Poisson image editing on a masked domain: Laplace hole filling, seamless cloning, reconstruction "
      "from a gradient field (docs/poisson.md). Masks: white = hole / region.",
      "poisson"};
  app.require_subcommand(1);
  app.fallthrough();  // the options, --json and --quiet may also follow the subcommand
  bool quiet = false;
  std::string json_path;
  PoissonOptions options;
  OptionBinder binder(app);
  binder.Bind(&options);
  AddJsonOption(app, &json_path);
  AddQuietFlag(app, &quiet);

  std::string image_path, mask_path, output_path;
  CLI::App* fill =
      app.add_subcommand("fill", "fill the masked pixels smoothly from their surroundings (Laplace)");
  fill->add_option("image", image_path, "input image (8/16-bit or float, any channels)")->required();
  fill->add_option("--mask", mask_path, "hole mask (white = hole), same size")->required();
  fill->add_option("-o,--output", output_path, "output image (.png/.jpg 8-bit, .exr/.tif float)")->required();

  std::string source_path, target_path, offset_text = "0,0";
  CLI::App* clone = app.add_subcommand("clone", "seamlessly clone a masked region of SOURCE into TARGET");
  clone->add_option("source", source_path, "source image")->required();
  clone->add_option("--mask", mask_path, "region of the source to clone (white), source size")->required();
  clone->add_option("--target", target_path, "target image, same channels as the source")->required();
  clone->add_option("--offset", offset_text, "X,Y: target pixel where source pixel (0,0) lands")
      ->capture_default_str();
  clone->add_option("-o,--output", output_path, "output image")->required();

  std::string gx_path, gy_path, boundary_path;
  CLI::App* reconstruct = app.add_subcommand(
      "reconstruct", "solve for the image whose gradients are (GX, GY) in the mask, BOUNDARY around it");
  reconstruct->add_option("--gx", gx_path, "horizontal forward differences I(x+1) - I(x) (float, .exr/.tif)")
      ->required();
  reconstruct->add_option("--gy", gy_path, "vertical forward differences I(y+1) - I(y) (float)")->required();
  reconstruct->add_option("--boundary", boundary_path, "image giving the values around the mask")->required();
  reconstruct->add_option("--mask", mask_path, "domain to reconstruct (white), same size")->required();
  reconstruct->add_option("-o,--output", output_path, "output image (.exr/.tif float, or .png)")->required();

  for (CLI::App* sub : {fill, clone, reconstruct}) {
    sub->footer(
        "Solver options (--solver, --tolerance, ...), --options, --json and --quiet: `lidarshop poisson "
        "--help`; they may follow the subcommand.");
  }
  return RunCommand(
      app, argc, argv,
      [&]() {
        binder.Validate(options);
        CheckOutputPath(output_path,
                        {image_path, mask_path, source_path, target_path, gx_path, gy_path, boundary_path});
        CheckOutputFile(
            "--json", json_path, {},
            {image_path, mask_path, source_path, target_path, gx_path, gy_path, boundary_path, output_path});
        PoissonResult result;
        if (*fill) {
          const cv::Mat image = ReadImage(image_path);
          const cv::Mat mask = ReadMask(mask_path, image.size(), image_path);
          const PoissonSystem system = PreparePoisson(mask, options);
          cv::Mat input;
          image.convertTo(input, CV_32F);
          result = FillLaplace(system, input);
          WriteResult(output_path, result.image, IntegerDepth(image));
        } else if (*clone) {
          const cv::Point offset = ParseOffset(offset_text);
          const cv::Mat source = ReadImage(source_path);
          const cv::Mat target = ReadImage(target_path);
          const cv::Mat mask = ReadMask(mask_path, source.size(), source_path);
          if (source.channels() != target.channels()) {
            ThrowInputError(target_path, "", "",
                            fmt::format("the target has {} channel(s), the source {} has {}",
                                        target.channels(), source_path, source.channels()));
          }
          cv::Mat source_float, target_float;
          source.convertTo(source_float, CV_32F);
          target.convertTo(target_float, CV_32F);
          result = SeamlessClone(source_float, mask, target_float, offset, options);
          WriteResult(output_path, result.image, IntegerDepth(target));
        } else {
          const cv::Mat boundary = ReadImage(boundary_path);
          const cv::Mat gx = ReadFloat(gx_path), gy = ReadFloat(gy_path);
          for (const auto& [path, field] : {std::pair{gx_path, &gx}, std::pair{gy_path, &gy}}) {
            if (field->size() != boundary.size() || field->channels() != boundary.channels()) {
              ThrowInputError(path, "", "",
                              fmt::format("{}x{} with {} channel(s), but {} is {}x{} with {}", field->cols,
                                          field->rows, field->channels(), boundary_path, boundary.cols,
                                          boundary.rows, boundary.channels()));
            }
          }
          const cv::Mat mask = ReadMask(mask_path, boundary.size(), boundary_path);
          const PoissonSystem system = PreparePoisson(mask, options);
          cv::Mat boundary_float;
          boundary.convertTo(boundary_float, CV_32F);
          result = ReconstructFromGradients(system, boundary_float, gx, gy);
          WriteResult(output_path, result.image, IntegerDepth(boundary));
        }
        Summarize(fmt::format("{} unknowns; {}", result.unknowns, result.Summary()));
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(result)));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
