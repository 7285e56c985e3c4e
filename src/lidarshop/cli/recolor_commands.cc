// lidarshop resection | recolor | images | align | photo: photos and scans (recolor/, docs/recolor.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_image_camera.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/auto_resection.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/e57_camera.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/recolor/station_recolor.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"

namespace lidarshop::cli {
namespace {

// Refuses to write onto an input (inputs are never modified).
void CheckNotInput(const std::string& output, const std::vector<std::string>& inputs) {
  for (const std::string& input : inputs) {
    std::error_code error;
    if (!input.empty() && std::filesystem::equivalent(output, input, error))
      throw OptionsError(
          fmt::format("the output {} is an input: lidarshop never writes onto its inputs", output));
  }
}

Scan ReadOneScan(const std::string& path, int index, const std::string& flag) {
  return PickScan(ReadScanFileAndWarn(path), index, flag);
}

// The entry of `images` named `key` or numbered `key`.
const E57Image& FindImage(const std::vector<E57Image>& images, const std::string& key,
                          const std::string& path) {
  for (const E57Image& image : images) {
    if (image.name == key) return image;
  }
  try {
    const size_t index = std::stoul(key);
    if (index < images.size()) return images[index];
  } catch (const std::exception&) {
  }
  throw OptionsError(fmt::format("{} has no image '{}' ({} image(s); `lidarshop images {}` lists them)", path,
                                 key, images.size(), path));
}

ResectionResult RunResection(const Correspondences& pairs, const ResectionOptions& options,
                             const std::string& intrinsics_path, const std::string& what) {
  if (pairs.kind != PairKind::kPixelPoint)
    ThrowInputError(what, "", "pairs", "resection needs pixel/point (or pixel/cell) pairs");
  if (intrinsics_path.empty()) return Resection(pairs.pixel_point, options, what);
  return ResectWithIntrinsics(pairs.pixel_point, ReadCameraJson(intrinsics_path), options, what);
}

// The photo's size comes from the photo, --size or the correspondence file, not from flags.
void AddResectionOptions(CLI::App& app, OptionBinder& binder, ResectionOptions* options,
                         std::string* intrinsics_path, const std::string& group) {
  binder.Bind(options, {.skip = {"width_px", "height_px"},
                        .flags = {{"ransac_threshold_px", "--threshold"},
                                  {"ransac_iterations", "--iterations"},
                                  {"radial_coefficients", "--radial"}},
                        .group = group});
  CLI::Option* intrinsics = app.add_option(
      "--intrinsics", *intrinsics_path,
      "camera JSON whose intrinsics are known: only the pose is estimated (planar targets too)");
  // An empty group name would hide the flag from --help (CLI11's way to hide options).
  if (!group.empty()) intrinsics->group(group);
}

// --auto: AutoResectionOptions' flags are --auto-<key> (its seed, threshold and iterations are not the
// pair resection's).
void AddAutoResectionOptions(OptionBinder& binder, AutoResectionOptions* options, std::string* rough_path,
                             CLI::App& app, const std::string& group) {
  BindSettings settings;
  for (const FieldInfo& field : InfoOf<AutoResectionOptions>().fields) {
    std::string flag = "--auto-" + field.key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    settings.flags[field.key] = flag;
  }
  settings.group = group;
  binder.Bind(options, settings);
  app.add_option(
         "--rough-camera", *rough_path,
         "with --auto: camera JSON whose pose is a rough guess to start from (instead of a search from "
         "the scanner centre); its intrinsics are not used")
      ->group(group);
}

AutoResectionResult RunAutoResection(const Scan& scan, const cv::Mat& photo,
                                     const AutoResectionOptions& options, const std::string& intrinsics_path,
                                     const std::string& rough_path, const std::string& what) {
  std::optional<PinholeCamera> intrinsics;
  std::optional<Eigen::Matrix4d> rough;
  if (!intrinsics_path.empty()) intrinsics = ReadCameraJson(intrinsics_path);
  if (!rough_path.empty()) rough = ReadCameraModelJson(rough_path).world_from_camera;
  return AutoResection(scan, photo, options, intrinsics, rough, what);
}

}  // namespace

int RunResection(int argc, char** argv) {
  CLI::App app{
      "Resection: the camera of a photo from pixel <-> point correspondences (normalized DLT, RANSAC, "
      "Levenberg-Marquardt with distortion; docs/recolor.md). Prints the per-pair errors as JSON.",
      "resection"};
  std::string pairs_path, output, scan_path, photo_path, intrinsics_path, json_path = "-";
  std::vector<int> size;
  std::vector<std::string> auto_inputs;
  std::string rough_path;
  bool auto_mode = false;
  int scan_index = 0;
  ResectionOptions options;
  AutoResectionOptions auto_options;
  OptionBinder binder(app);
  app.add_option("--correspondences", pairs_path,
                 "C.json: {\"pairs\": [{\"pixel\": [u, v], \"point\": [x, y, z]}]}");
  app.add_flag("--auto", auto_mode,
               "no pairs: register the photo to the scan automatically (rendered views, SIFT, PnP RANSAC; "
               "recolor/auto_resection.h): resection --auto SCAN PHOTO -o CAM.json");
  app.add_option("inputs", auto_inputs, "with --auto: SCAN PHOTO (or --scan, --photo)")->expected(0, 2);
  app.add_option("-o,--output", output, "camera JSON to write")->required();
  app.add_option("--scan", scan_path, "the scan whose cells \"cell\": [row, col] refer to");
  app.add_option("--scan-index", scan_index, "which scan of --scan (from 0)");
  app.add_option("--photo", photo_path, "the photo (its size goes into the camera)");
  app.add_option("--size", size, "the photo's size: WIDTH HEIGHT (instead of --photo)")->expected(2);
  AddJsonOption(app, &json_path);
  AddResectionOptions(app, binder, &options, &intrinsics_path, "");
  AddAutoResectionOptions(binder, &auto_options, &rough_path, app, "Automatic resection (--auto)");
  return RunCommand(
      app, argc, argv,
      [&] {
        binder.Validate(options);
        if (auto_mode) {
          binder.Validate(auto_options);
          if (!pairs_path.empty()) throw OptionsError("--auto needs no --correspondences");
          if (!size.empty()) throw OptionsError("--auto takes the photo's size from the photo: no --size");
          if (auto_inputs.size() >= 1) {
            if (!scan_path.empty()) throw OptionsError("give the scan once (SCAN or --scan)");
            scan_path = auto_inputs[0];
          }
          if (auto_inputs.size() == 2) {
            if (!photo_path.empty()) throw OptionsError("give the photo once (PHOTO or --photo)");
            photo_path = auto_inputs[1];
          }
          if (scan_path.empty() || photo_path.empty())
            throw OptionsError("--auto needs a scan and a photo: resection --auto SCAN PHOTO -o CAM.json");
          CheckNotInput(output, {scan_path, photo_path, intrinsics_path, rough_path});
          CheckOutputFile("--json", json_path, {},
                          {scan_path, photo_path, intrinsics_path, rough_path, output});
          const Scan scan = ReadOneScan(scan_path, scan_index, "--scan-index");
          const cv::Mat photo = ReadImage(photo_path);
          const AutoResectionResult result =
              RunAutoResection(scan, photo, auto_options, intrinsics_path, rough_path, photo_path);
          WriteCameraJson(output, result.camera);
          WriteJsonOutput(json_path,
                          CommandJson(ToJson(auto_options), ToJson(SummarizeAutoResection(result))));
          PrintResultWarnings(result.warnings);
          Summarize(fmt::format("{} -> {}", result.Summary(), output));
          return 0;
        }
        if (!auto_inputs.empty()) throw OptionsError("SCAN PHOTO go with --auto");
        if (pairs_path.empty()) throw OptionsError("give --correspondences C.json, or --auto SCAN PHOTO");
        CheckNotInput(output, {pairs_path, scan_path, photo_path, intrinsics_path});
        CheckOutputFile("--json", json_path, {},
                        {pairs_path, scan_path, photo_path, intrinsics_path, output});
        Scan scan;
        if (!scan_path.empty()) scan = ReadOneScan(scan_path, scan_index, "--scan-index");
        const Correspondences pairs = ReadCorrespondences(pairs_path, scan_path.empty() ? nullptr : &scan);
        if (pairs.width_px > 0) options.width_px = pairs.width_px, options.height_px = pairs.height_px;
        if (!size.empty()) options.width_px = size[0], options.height_px = size[1];
        if (!photo_path.empty()) {
          const cv::Mat photo = ReadImage(photo_path);
          options.width_px = photo.cols, options.height_px = photo.rows;
        }
        if (options.width_px <= 0)
          throw OptionsError(
              "the photo's size is unknown: give --photo, --size W H or \"image_size_px\" in " + pairs_path);
        const ResectionResult result = RunResection(pairs, options, intrinsics_path, pairs_path);
        WriteCameraJson(output, result.camera);
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(SummarizeResection(result))));
        PrintResultWarnings(result.warnings);
        Summarize(fmt::format("{} -> {}", result.Summary(), output));
        return 0;
      },
      &binder);
}

int RunRecolor(int argc, char** argv) {
  CLI::App app{
      "Recolour a scan from a photo: occlusion-aware projection (thesis 3.2.2.1, docs/recolor.md). Points "
      "the camera does not see keep their colour.",
      "recolor"};
  std::string scan_path, image_key, pairs_path, output, mask_path, uncertain_path, json_path = "-";
  std::vector<std::string> photo_paths, camera_paths;
  int scan_index = 0;
  RecolorOptions options;
  ResectionOptions resection;
  std::string intrinsics_path;
  OptionBinder binder(app);
  app.add_option("scan", scan_path, "scan file to recolour")->required();
  app.add_option(
         "--photo", photo_paths,
         "the photo (.jpg, .png); repeated, each with its --camera (any model), the photos colour the "
         "scan together as a station's (as --from-e57-images)")
      ->allow_extra_args(false);
  app.add_option("--image", image_key,
                 "an images2D entry of the E57 scan (name or index) instead of --photo");
  app.add_option("--camera", camera_paths,
                 "camera JSON (lidarshop resection); with several --photo, one per photo in their order")
      ->allow_extra_args(false);
  app.add_option("--correspondences", pairs_path, "pixel <-> point or cell pairs: resection first");
  app.add_option("-o,--output", output, "recoloured scan to write (format from the extension)")->required();
  app.add_option("--recolored-mask", mask_path, "PNG of the scan grid: 255 = took the photo's colour");
  app.add_option("--uncertain-mask", uncertain_path,
                 "PNG of the scan grid: 255 = kept its colour near an occluding edge (uncertain)");
  bool from_e57_images = false;
  std::string photo_index_mask_path;
  app.add_flag("--from-e57-images", from_e57_images,
               "colour from every images2D entry of the E57 scan that holds a camera (pinhole, spherical, "
               "cylindrical) and belongs to the scan: per point the best photo that sees it, exposure "
               "equalised to photo 0's, seams blended in the gradient domain (recolor/station_recolor.h)");
  app.add_option("--photo-index-mask", photo_index_mask_path,
                 "--from-e57-images or several --photo: 16-bit PNG of the scan grid, 1 + the index of the "
                 "photo that coloured "
                 "each cell, 0 where none did");
  AddScanIndexOption(app, &scan_index);
  AddJsonOption(app, &json_path);
  binder.Bind(&options,
              {.flags = {{"silhouette_margin_px", "--margin"}, {"depth_tolerance_m", "--depth-tolerance"}}});
  AddResectionOptions(app, binder, &resection, &intrinsics_path, "Resection (with --correspondences)");
  bool auto_mode = false;
  std::string rough_path;
  AutoResectionOptions auto_options;
  app.add_flag("--auto", auto_mode,
               "no camera, no pairs: register the photo to the scan automatically first "
               "(recolor/auto_resection.h; --intrinsics gives known intrinsics)");
  AddAutoResectionOptions(binder, &auto_options, &rough_path, app, "Automatic resection (--auto)");
  // Colouring from several photos at once, and what it writes (--from-e57-images, repeated --photo).
  // `carried`: the input E57's images of this scan, written on with it when the output is an E57 (a station's
  // photos belong with its scan; a recoloured E57 without them could not be coloured again).
  double read_seconds = 0;  // the scan file (and with --from-e57-images its photos) read and decoded
  const auto colour_station = [&](const Scan& scan, const std::vector<CameraPhoto>& photos,
                                  std::vector<RecolorPhotoUsed> used,
                                  std::vector<RecolorPhotoSkipped> skipped,
                                  const std::vector<E57Image>& carried) {
    PhotosRecolorOptions photo_options;
    photo_options.visibility = options;
    // The station's own cameras: the guard only when asked for (PhotosRecolorOptions::visibility).
    if (app.count("--edge-guard") == 0) photo_options.visibility.edge_guard = false;
    const PhotosRecolorResult result = RecolorFromPhotos(scan, photos, photo_options);
    const auto write_start = std::chrono::steady_clock::now();
    if (FileExtension(output) == "e57" && !carried.empty()) {
      WriteE57(output, {result.scan}, carried, E57WriteOptions());
    } else {
      WriteScanFile(output, {result.scan});
      if (!carried.empty())
        PrintWarnings({fmt::format("{}: the station's {} photo(s) are not carried on (only E57 holds photos)",
                                   output, carried.size())});
    }
    if (!photo_index_mask_path.empty()) WriteImage(photo_index_mask_path, result.photo_index);
    const double write_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
    PhotosRecolorSummary summary = SummarizePhotosRecolor(result, std::move(used), std::move(skipped));
    summary.seconds.read = read_seconds;
    summary.seconds.write = write_seconds;
    WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(summary)));
    Summarize(fmt::format("{} -> {}", result.Summary(), output));
    return 0;
  };
  return RunCommand(
      app, argc, argv,
      [&] {
        binder.Validate(options);
        binder.Validate(resection);
        binder.Validate(auto_options);
        if (auto_mode &&
            (photo_paths.size() > 1 || from_e57_images || !camera_paths.empty() || !pairs_path.empty()))
          throw OptionsError(
              "--auto finds the camera of one photo (--photo or --image): no --camera, --correspondences, "
              "--from-e57-images nor several --photo");
        if (!auto_mode && !rough_path.empty()) throw OptionsError("--rough-camera goes with --auto");
        const std::string photo_path = photo_paths.size() == 1 ? photo_paths[0] : "";
        const std::string camera_path = camera_paths.size() == 1 ? camera_paths[0] : "";
        std::vector<std::string> inputs = {scan_path, pairs_path};
        inputs.insert(inputs.end(), photo_paths.begin(), photo_paths.end());
        inputs.insert(inputs.end(), camera_paths.begin(), camera_paths.end());
        {
          std::vector<std::string> others = inputs;
          others.insert(others.end(), {output, mask_path, uncertain_path, photo_index_mask_path});
          CheckOutputFile("--json", json_path, {}, others);
        }
        if (photo_paths.size() >= 2) {
          if (camera_paths.size() != photo_paths.size())
            throw OptionsError(
                fmt::format("{} --photo need as many --camera, one per photo in their order; got {}",
                            photo_paths.size(), camera_paths.size()));
          if (from_e57_images || !image_key.empty() || !pairs_path.empty() || !mask_path.empty() ||
              !uncertain_path.empty())
            throw OptionsError(
                "several --photo colour the scan as a station: no --from-e57-images, --image, "
                "--correspondences, --recolored-mask nor --uncertain-mask");
          CheckNotInput(output, inputs);
          if (!photo_index_mask_path.empty()) {
            CheckNotInput(photo_index_mask_path, inputs);
            CheckOutputPath(photo_index_mask_path, {scan_path, output});
          }
          const auto read_start = std::chrono::steady_clock::now();
          const Scan scan = ReadOneScan(scan_path, scan_index, ScanIndexFlag(app));
          read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
          std::vector<CameraPhoto> photos;
          std::vector<RecolorPhotoUsed> used;
          for (size_t i = 0; i < photo_paths.size(); ++i) {
            CameraPhoto photo{ReadImage(photo_paths[i]), ReadCameraModelJson(camera_paths[i])};
            if (photo.image.type() != CV_8UC3)
              ThrowInputError(photo_paths[i], "", "", "expected an 8-bit RGB photo");
            if (photo.image.cols != photo.camera.width_px() || photo.image.rows != photo.camera.height_px())
              ThrowInputError(camera_paths[i], "", "width_px",
                              fmt::format("the camera is {} x {} pixels, its photo {} is {} x {}",
                                          photo.camera.width_px(), photo.camera.height_px(), photo_paths[i],
                                          photo.image.cols, photo.image.rows));
            used.push_back({.index = static_cast<int>(i),
                            .name = photo_paths[i],
                            .model = CameraModelName(photo.camera.model)});
            photos.push_back(std::move(photo));
          }
          return colour_station(scan, photos, std::move(used), {}, {});
        }
        if (camera_paths.size() > 1) throw OptionsError("several --camera need as many --photo");
        if (!photo_index_mask_path.empty() && !from_e57_images)
          throw OptionsError("--photo-index-mask goes with --from-e57-images or several --photo");
        if (from_e57_images) {
          if (!photo_path.empty() || !image_key.empty() || !camera_path.empty() || !pairs_path.empty() ||
              !mask_path.empty() || !uncertain_path.empty())
            throw OptionsError(
                "--from-e57-images takes the photos and cameras from the file: no --photo, --image, "
                "--camera, "
                "--correspondences, --recolored-mask nor --uncertain-mask");
          if (FileExtension(scan_path) != "e57")
            throw OptionsError("--from-e57-images needs an E57 scan file");
          CheckNotInput(output, {scan_path});
          if (!photo_index_mask_path.empty()) {
            CheckNotInput(photo_index_mask_path, {scan_path});
            CheckOutputPath(photo_index_mask_path, {scan_path, output});
          }
          const auto read_start = std::chrono::steady_clock::now();
          E57File file = ReadE57AndWarn(scan_path);  // once: a station can be hundreds of MB
          read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
          if (scan_index < 0 || scan_index >= static_cast<int>(file.scans.size()))
            throw OptionsError(fmt::format("{} {} is out of range: {} holds {} scan(s)", ScanIndexFlag(app),
                                           scan_index, scan_path, file.scans.size()));
          const E57StationPhotos station = StationPhotosOfE57(file, scan_index);
          const std::vector<CameraPhoto>& photos = station.photos;
          std::vector<RecolorPhotoUsed> used;
          std::vector<RecolorPhotoSkipped> skipped;
          for (size_t k = 0; k < photos.size(); ++k) {
            const int i = station.image_index[k];
            used.push_back(
                {.index = i, .name = file.images[i].name, .model = CameraModelName(photos[k].camera.model)});
          }
          for (const E57StationPhotos::Skipped& skip : station.skipped)
            skipped.push_back(
                {.index = skip.image_index, .name = file.images[skip.image_index].name, .why = skip.why});
          if (photos.empty())
            ThrowInputError(scan_path, "images2D", "",
                            fmt::format("no image of scan {} holds a photo with a camera ({} image(s); "
                                        "`lidarshop images {}` lists them)",
                                        scan_index, file.images.size(), scan_path));
          // This scan's images (and those of no scan), belonging to scan 0 of the output.
          std::vector<E57Image> carried;
          for (E57Image& image : file.images) {
            if (image.associated_scan != scan_index && image.associated_scan != -1) continue;
            if (image.associated_scan == scan_index) image.associated_scan = 0;
            carried.push_back(std::move(image));
          }
          const Scan scan = std::move(file.scans[scan_index]);
          file = E57File();
          return colour_station(scan, photos, std::move(used), std::move(skipped), carried);
        }
        if (photo_path.empty() == image_key.empty())
          throw OptionsError("give exactly one of --photo and --image");
        CheckNotInput(output, {scan_path, photo_path, camera_path, pairs_path});
        if (!mask_path.empty()) CheckNotInput(mask_path, {scan_path, photo_path, camera_path, pairs_path});
        if (!uncertain_path.empty())
          CheckOutputPath(uncertain_path,
                          {scan_path, photo_path, camera_path, pairs_path, output, mask_path});
        const Scan scan = ReadOneScan(scan_path, scan_index, ScanIndexFlag(app));
        cv::Mat photo;
        PinholeCamera camera;
        bool have_camera = false;
        std::optional<ResectionSummary> resection_summary;
        std::optional<AutoResectionSummary> auto_summary;
        if (!image_key.empty()) {
          if (FileExtension(scan_path) != "e57") throw OptionsError("--image needs an E57 scan file");
          const E57File file = ReadE57(scan_path);  // ReadOneScan printed the warnings
          const E57Image& image = FindImage(file.images, image_key, scan_path);
          if (image.image.empty())
            ThrowInputError(scan_path, "images2D " + image.name, "", image.decode_error);
          photo = image.image;
          std::string why;
          have_camera = !auto_mode && camera_path.empty() && pairs_path.empty() &&
                        CameraFromE57Image(image, &camera, &why);
          if (!have_camera && !auto_mode && camera_path.empty() && pairs_path.empty())
            throw OptionsError(why);
        } else {
          photo = ReadImage(photo_path);
          if (photo.type() != CV_8UC3) ThrowInputError(photo_path, "", "", "expected an 8-bit RGB photo");
        }
        if (!camera_path.empty() && !pairs_path.empty())
          throw OptionsError("give --camera or --correspondences, not both");
        if (auto_mode) {
          const AutoResectionResult result =
              RunAutoResection(scan, photo, auto_options, intrinsics_path, rough_path,
                               photo_path.empty() ? image_key : photo_path);
          fmt::print(stderr, "{}\n", result.Summary());
          auto_summary = SummarizeAutoResection(result);
          auto_summary->options = auto_options;
          camera = result.camera;
          // The edge guard's margin follows the camera's accuracy, as with pairs.
          options.camera_uncertainty_px = std::max(options.camera_uncertainty_px, 2 * result.rms_px);
        } else if (!camera_path.empty()) {
          camera = ReadCameraJson(camera_path);
        } else if (!pairs_path.empty()) {
          resection.width_px = photo.cols, resection.height_px = photo.rows;
          const ResectionResult result =
              RunResection(ReadCorrespondences(pairs_path, &scan), resection, intrinsics_path, pairs_path);
          fmt::print(stderr, "resection: {}\n", result.Summary());
          PrintResultWarnings(result.warnings);
          resection_summary = SummarizeResection(result);
          resection_summary->options = resection;
          camera = result.camera;
          // The edge guard's margin follows the resection: a camera is good to about twice its RMS.
          options.camera_uncertainty_px = std::max(options.camera_uncertainty_px, 2 * result.rms_px);
        } else if (!have_camera) {
          throw OptionsError("give --camera, --correspondences or --auto");
        }
        const RecolorResult result = RecolorScan(scan, photo, camera, options);
        WriteScanFile(output, {result.scan});
        if (!mask_path.empty()) WriteImage(mask_path, result.recolored);
        if (!uncertain_path.empty()) WriteImage(uncertain_path, result.uncertain_mask);
        // The resection's warnings (its RMS) and the recolouring's (the colours disagree), in that order.
        const RecolorSummary summary = SummarizeRecolor(result, resection_summary, auto_summary);
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(summary)));
        PrintResultWarnings(result.warnings);
        Summarize(fmt::format("{} -> {}", result.Summary(), output));
        return 0;
      },
      &binder);
}

int RunImages(int argc, char** argv) {
  CLI::App app{
      "List the photos (images2D) of an E57 file as JSON, each with its representation and camera model; "
      "--extract writes each photo's stored bytes as they "
      "are (JPEG or PNG, EXIF kept).",
      "images"};
  std::string path, folder, json_path = "-";
  app.add_option("file", path, "E57 file")->required();
  app.add_option("--extract", folder,
                 "folder to write <index>_<name>.jpg / .png into (created): the stored blob, byte for byte; "
                 "a blob that does not decode is not written");
  AddJsonOption(app, &json_path);
  return RunCommand(app, argc, argv, [&] {
    if (FileExtension(path) != "e57") throw OptionsError(path + " is not an .e57 file");
    CheckOutputFile("--json", json_path, {}, {path});
    const E57File file = ReadE57AndWarn(path);
    E57ImagesSummary summary{.file = path, .images = SummarizeE57Images(file.images)};
    if (!folder.empty()) {
      std::filesystem::create_directories(folder);
      for (size_t i = 0; i < file.images.size(); ++i) {
        const E57Image& image = file.images[i];
        // The stored bytes (re-encoding would lose the JPEG's EXIF, where the camera's focal length lives,
        // and grow it ~6x as PNG); a blob that does not decode (e.g. zero-filled) is not a photo.
        if (image.image.empty() || image.encoded.empty()) continue;
        std::string name = image.name;
        for (char& c : name) {
          if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
        }
        const std::string out =
            (std::filesystem::path(folder) /
             fmt::format("{:02}_{}.{}", i, name, image.encoding == "jpeg" ? "jpg" : "png"))
                .string();
        CheckOutputPath(out, {path, json_path == "-" ? "" : json_path});
        WriteFileAtomically(out, [&](std::ostream& stream) {
          stream.write(reinterpret_cast<const char*>(image.encoded.data()),
                       static_cast<std::streamsize>(image.encoded.size()));
        });
        summary.images[i].extracted = out;
      }
    }
    WriteJsonOutput(json_path, ToJson(summary));
    const auto extracted =
        std::count_if(summary.images.begin(), summary.images.end(),
                      [](const E57ImageSummary& image) { return !image.extracted.empty(); });
    Summarize(fmt::format("{}: {} image(s){}", path, file.images.size(),
                          folder.empty() ? "" : fmt::format(", {} written to {}", extracted, folder)));
    return 0;
  });
}

int RunAlign(int argc, char** argv) {
  CLI::App app{
      "Transforms from correspondences: scan <-> scan landmarks (\"source\"/\"target\") give a rigid or "
      "scaled 4x4 (Umeyama); photo <-> photo pairs (\"pixel_a\"/\"pixel_b\") a 3x3 homography or "
      "fundamental matrix. Writes the matrix as text rows, prints residuals as JSON.",
      "align"};
  std::string pairs_path, output, json_path = "-";
  AlignOptions options;
  OptionBinder binder(app);
  app.add_option("--correspondences", pairs_path, "C.json")->required();
  app.add_option("-o,--output", output, "T.txt to write")->required();
  AddJsonOption(app, &json_path);
  binder.Bind(&options, {.flags = {{"threshold_px", "--threshold"}}});
  return RunCommand(
      app, argc, argv,
      [&] {
        binder.Validate(options);
        CheckNotInput(output, {pairs_path});
        CheckOutputFile("--json", json_path, {}, {pairs_path, output});
        const Correspondences pairs = ReadCorrespondences(pairs_path);
        nlohmann::ordered_json json;
        std::string text;
        if (pairs.kind == PairKind::kLandmark) {
          const LandmarkAlignment result = AlignLandmarks(pairs.landmarks, options.scale, pairs_path);
          for (int r = 0; r < 4; ++r) {
            const Eigen::RowVector4d row = result.target_from_source.row(r);
            text += fmt::format("{:.17g} {:.17g} {:.17g} {:.17g}\n", row[0], row[1], row[2], row[3]);
          }
          json = ToJson(result);
          Summarize(
              fmt::format("{} transform, RMS {:.4g} m -> {}", ToString(result.model), result.rms_m, output));
        } else if (pairs.kind == PairKind::kPixelPixel) {
          const PhotoPairModel result = EstimatePhotoModel(pairs.pixel_pixel, options, pairs_path);
          for (int r = 0; r < 3; ++r)
            text += fmt::format("{:.17g} {:.17g} {:.17g}\n", result.matrix(r, 0), result.matrix(r, 1),
                                result.matrix(r, 2));
          json = ToJson(result);
          Summarize(fmt::format("{}, RMS {:.3g} px -> {}", ToString(result.model), result.rms_px, output));
        } else {
          ThrowInputError(pairs_path, "", "pairs", "pixel/point pairs: use `lidarshop resection`");
        }
        WriteTextAtomically(output, text);
        WriteJsonOutput(json_path, CommandJson(ToJson(options), json));
        return 0;
      },
      &binder);
}

int RunPhoto(int argc, char** argv) {
  CLI::App app{
      "The synthetic camera: render what a camera (pinhole, fisheye, spherical or cylindrical: the camera "
      "JSON's \"model\") sees in a scene, with the scanner's colours.",
      "photo"};
  std::string scene_path, camera_path, output, json_path;
  PhotoOptions options;
  OptionBinder binder(app);
  app.add_option("scene", scene_path, "scene JSON (docs/scene-format.md)")->required();
  app.add_option("--camera", camera_path,
                 "camera JSON (geometry/camera_model.h; \"model\": pinhole (default), fisheye, spherical, "
                 "cylindrical)")
      ->required();
  app.add_option("-o,--output", output, "photo to write (.png, .jpg)")->required();
  AddJsonOption(app, &json_path);
  binder.Bind(&options, {.flags = {{"samples_per_axis", "--samples"}}});
  return RunCommand(
      app, argc, argv,
      [&] {
        binder.Validate(options);
        CheckNotInput(output, {scene_path, camera_path});
        CheckOutputFile("--json", json_path, {}, {scene_path, camera_path, output});
        const SceneDescription scene = LoadScene(scene_path);
        PrintWarnings(scene.warnings);
        const Camera camera = ReadCameraModelJson(camera_path);
        const Photo photo = RenderPhoto(scene, camera, options);
        WriteImage(output, photo.image);
        const PhotoSummary summary = SummarizePhoto(photo, camera);
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(summary)));
        Summarize(fmt::format("{} x {} photo, {} pixels see the scene -> {}", summary.width_px,
                              summary.height_px, summary.scene_pixels, output));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
