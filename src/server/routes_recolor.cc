// Routes for the three kinds of correspondences of the thesis's selection tool (3.2.1, recolor/; docs/api.md):
//   photo <-> scan   pixel <-> cell or point: resection, then occlusion-aware recolouring (an edit)
//   scan <-> scan    landmark cells in two open scans: a rigid transform (Umeyama) that registers this scan
//                    to the other (an edit of its pose), or a similarity reported only
//   photo <-> photo  pixel pairs between the photo and a second one: a homography or fundamental matrix
//                    with per-pair errors (the scan does not change)
#include <algorithm>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "http.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/recolor/station_recolor.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "replies.h"

namespace lidarshop::server {

namespace {

// ?slot=a (the photo to recolour from, the default) or ?slot=b (the second photo of photo <-> photo pairs).
cv::Mat* PhotoSlot(Document& document, const httplib::Request& request, httplib::Response& response) {
  const std::string slot = request.has_param("slot") ? request.get_param_value("slot") : std::string("a");
  if (slot == "a") return &document.photo;
  if (slot == "b") return &document.photo_b;
  SendError(response, 400, fmt::format("slot '{}': expected a or b", slot));
  return nullptr;
}

// The pairs of `body` through the library's correspondence parser (recolor/correspondences.h): every pair
// names its kind by its keys; all must be of `kind`.
Correspondences ParsePairs(const nlohmann::json& body, PairKind kind, const Scan* scan) {
  if (!body.contains("pairs") || !body["pairs"].is_array() || body["pairs"].size() > 10000)
    throw OptionsFieldError("pairs", "expected a list of at most 10000 pairs");
  Correspondences pairs =
      ParseCorrespondences(nlohmann::json{{"pairs", body["pairs"]}}.dump(), "pairs", scan);
  if (pairs.size() > 0 && pairs.kind != kind) {
    throw OptionsFieldError(
        "pairs", fmt::format("{} pairs here; expected {} pairs", ToString(pairs.kind), ToString(kind)));
  }
  return pairs;
}

void CheckInside(const Eigen::Vector2d& pixel, const cv::Mat& photo, const std::string& key) {
  if (!(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < photo.cols && pixel.y() < photo.rows)) {
    throw OptionsFieldError(key, fmt::format("pixel ({}, {}) is outside the {} x {} photo", pixel.x(),
                                             pixel.y(), photo.cols, photo.rows));
  }
}

// Photo <-> scan: resection from the pairs, then occlusion-aware recolouring; an undoable edit (a job).
void Recolor(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
             httplib::Response& response) {
  std::vector<PixelPointPair> pairs;
  ResectionOptions resection;
  {
    std::lock_guard lock(document->mutex);
    if (document->photo.empty()) return SendError(response, 400, "upload a photo first (POST .../photo)");
    try {
      pairs = ParsePairs(body, PairKind::kPixelPoint, &document->now.scan).pixel_point;
    } catch (const InputError& error) {
      throw OptionsError(error.what());  // a bad cell or pair is the request's fault: 400
    }
    for (size_t i = 0; i < pairs.size(); ++i)
      CheckInside(pairs[i].pixel_px, document->photo, fmt::format("pairs[{}]", i));
    resection.width_px = document->photo.cols;
    resection.height_px = document->photo.rows;
  }
  try {
    CheckResectionInput(pairs, resection.degenerate_ratio, "pairs");
  } catch (const InputError& error) {
    throw OptionsError(error.what());  // pairs that cannot determine a camera
  }
  const int undo_depth = state.options.undo_depth;
  StartJob(
      state, document, "recolor",
      [document, pairs, resection, undo_depth](Progress& progress) {
        Snapshot start;
        cv::Mat photo;
        {
          std::lock_guard lock(document->mutex);
          start = document->now;
          photo = document->photo;
        }
        progress.Restart("resection", 2);
        const ResectionResult camera = Resection(pairs, resection, "pairs");
        progress.Advance();
        // The edge guard's margin follows the resection, as the CLI's (recolor/recolor.h).
        RecolorOptions recolor_options;
        recolor_options.camera_uncertainty_px =
            std::max(recolor_options.camera_uncertainty_px, 2 * camera.rms_px);
        const RecolorResult recolored = RecolorScan(start.scan, photo, camera.camera, recolor_options);
        progress.Advance();
        std::lock_guard lock(document->mutex);
        Snapshot next = document->now;
        next.scan = recolored.scan;
        Commit(*document, std::move(next), undo_depth);
        // What looks wrong (the resection's RMS, colours that disagree with the scan's own), one sentence each.
        std::vector<std::string> warnings = camera.warnings;
        warnings.insert(warnings.end(), recolored.warnings.begin(), recolored.warnings.end());
        return ToJson(RecolorReply{
            camera.num_inliers, pairs.size(), camera.rms_px, camera.reprojection_error_px, camera.inlier,
            recolored.recolored_count, recolored.hidden, recolored.uncertain, recolored.outside_image,
            camera.Summary() + "; " + recolored.Summary(), warnings, document->version});
      },
      response);
}

// The station's own photos: every photo of the scan's E57 file that holds a camera (pinhole, spherical,
// cylindrical; io/e57_image_camera.h) colours the cells it sees best (recolor/station_recolor.h, as `recolor
// --from-e57-images`); an undoable edit (a job). 400 when no photo holds a camera, saying why for each.
void RecolorStation(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
                    httplib::Response& response) {
  const PhotosRecolorOptions options;  // the library's defaults, as the CLI's (no JSON form of its own yet)
  std::vector<CameraPhoto> photos;
  std::vector<StationPhotoEntry> used, skipped;
  {
    std::lock_guard lock(document->mutex);
    E57File file;  // the document's photos, as the file's scan 0 holds them (ImagesOfScan)
    file.images = document->e57_images;
    const E57StationPhotos station = StationPhotosOfE57(file, 0);  // as `recolor --from-e57-images`
    photos = station.photos;
    for (const int index : station.image_index)
      used.push_back({index, file.images[index].name, std::nullopt});
    for (const auto& [index, why] : station.skipped) skipped.push_back({index, file.images[index].name, why});
  }
  if (photos.empty()) {
    nlohmann::ordered_json skipped_json = nlohmann::ordered_json::array();
    for (const StationPhotoEntry& photo : skipped) skipped_json.push_back(ToJson(photo));
    throw OptionsFieldError(
        "photos",
        fmt::format("none of the scan's {} E57 photo(s) holds a camera to colour "
                    "from{}",
                    skipped.size(), skipped.empty() ? "" : ": " + Excerpt(skipped_json.dump(), 300)));
  }
  const int undo_depth = state.options.undo_depth;
  StartJob(
      state, document, "recolor-station",
      [document, photos, options, used, skipped, undo_depth](Progress& progress) {
        Snapshot start;
        {
          std::lock_guard lock(document->mutex);
          start = document->now;
        }
        progress.Restart("colour from the station's photos", 1);
        const PhotosRecolorResult result = RecolorFromPhotos(start.scan, photos, options);
        progress.Advance();
        std::lock_guard lock(document->mutex);
        Snapshot next = document->now;
        next.scan = result.scan;
        Commit(*document, std::move(next), undo_depth);
        return ToJson(RecolorStationReply{result.returns, result.coloured, result.constraints, used, skipped,
                                          result.Summary(), document->version});
      },
      response);
}

// A cell [row, col] of `pair[key]`, whole numbers.
std::pair<int, int> CellOf(const nlohmann::json& pair, const char* key, const std::string& place) {
  const auto it = pair.find(key);
  if (it == pair.end() || !it->is_array() || it->size() != 2 || !(*it)[0].is_number_integer() ||
      !(*it)[1].is_number_integer()) {
    throw OptionsFieldError(place + "." + key, "expected [row, col] whole numbers");
  }
  return {(*it)[0].get<int>(), (*it)[1].get<int>()};
}

// Scan <-> scan: landmark cells in this scan and in another open one; Umeyama's fit. With "apply" (default)
// and no scale, this scan's pose becomes target_from_source · world_from_scanner: it is registered to the
// other (an undoable edit).
void Align(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
           httplib::Response& response) {
  if (!body.contains("target") || !body["target"].is_number_integer())
    throw OptionsFieldError("target", "expected the id of another open scan");
  const int target_id = body["target"].get<int>();
  if (target_id == document->id) throw OptionsFieldError("target", "align to another open scan, not itself");
  std::shared_ptr<Document> target;
  {
    std::lock_guard lock(state.documents_mutex);
    const auto found = state.documents.find(target_id);
    if (found != state.documents.end()) target = found->second;
  }
  if (!target) return SendError(response, 404, fmt::format("no open scan {}", target_id));
  const bool with_scale = body.value("with_scale", false);
  const bool apply = body.value("apply", true);
  if (with_scale && apply)
    throw OptionsFieldError("apply", "a scaled transform cannot be a scanner pose; send \"apply\": false");
  const nlohmann::json list = body.value("pairs", nlohmann::json::array());
  if (!list.is_array() || list.size() > 10000) throw OptionsFieldError("pairs", "expected a list of pairs");
  std::vector<PointPair> pairs(list.size());
  try {
    {
      std::lock_guard lock(target->mutex);
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string place = fmt::format("pairs[{}]", i);
        const auto [row, col] = CellOf(list[i], "target_cell", place);
        pairs[i].target = WorldPointOfCell(target->now.scan, row, col, "target scan", place);
      }
    }
    std::lock_guard lock(document->mutex);
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string place = fmt::format("pairs[{}]", i);
      const auto [row, col] = CellOf(list[i], "cell", place);
      pairs[i].source = WorldPointOfCell(document->now.scan, row, col, "this scan", place);
    }
    const LandmarkAlignment fit = AlignLandmarks(pairs, with_scale, "pairs");
    const Eigen::Matrix4d& t = fit.target_from_source;
    if (apply) {
      Snapshot next = document->now;
      next.scan.world_from_scanner = t * document->now.scan.world_from_scanner;
      next.behind.world_from_scanner = next.scan.world_from_scanner;  // the second layer shares the pose
      Commit(*document, std::move(next), state.options.undo_depth);
    }
    SendJson(response, Joined(ToJson(fit), ToJson(AlignReply{std::vector<double>(t.data(), t.data() + 16),
                                                             apply, document->version})));
  } catch (const InputError& error) {
    throw OptionsError(error.what());  // cells without a return, too few or collinear landmarks
  }
}

// Photo <-> photo: pixel_a in the photo, pixel_b in the second photo; a homography (>= 4 pairs) or a
// fundamental matrix (>= 8) by RANSAC, answered at once.
void MatchPhotos(State&, const std::shared_ptr<Document>& document, const nlohmann::json& body,
                 httplib::Response& response) {
  // The body's "model" and "threshold_px" are AlignOptions' keys (the ranges of `lidarshop align`).
  nlohmann::json given = nlohmann::json::object();
  for (const char* key : {"model", "threshold_px"})
    if (body.contains(key)) given[key] = body.at(key);
  const AlignOptions options = FromJson<AlignOptions>(given);
  std::lock_guard lock(document->mutex);
  if (document->photo.empty() || document->photo_b.empty())
    return SendError(response, 400, "upload both photos first (POST .../photo and .../photo?slot=b)");
  try {
    const Correspondences pairs = ParsePairs(body, PairKind::kPixelPixel, nullptr);
    for (size_t i = 0; i < pairs.pixel_pixel.size(); ++i) {
      CheckInside(pairs.pixel_pixel[i].pixel_a, document->photo, fmt::format("pairs[{}].pixel_a", i));
      CheckInside(pairs.pixel_pixel[i].pixel_b, document->photo_b, fmt::format("pairs[{}].pixel_b", i));
    }
    const PhotoPairModel fit = EstimatePhotoModel(pairs.pixel_pixel, options, "pairs");
    PhotoMatchReply reply;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) reply.matrix_row_major.push_back(fit.matrix(r, c));
    SendJson(response, Joined(ToJson(fit), ToJson(reply)));
  } catch (const InputError& error) {
    throw OptionsError(error.what());  // too few pairs, no model found
  }
}

}  // namespace

void AddRecolorRoutes(State& state) {
  httplib::Server& http = state.http;
  // A photo as the request body (PNG or JPEG bytes); kept with the document.
  http.Post(
      R"(/api/docs/(\d+)/photo)", [&state](const httplib::Request& request, httplib::Response& response) {
        auto document = state.FindDocument(request, response);
        if (!document) return;
        {
          std::lock_guard lock(document->mutex);
          if (!PhotoSlot(*document, request, response)) return;  // 400 for an unknown slot
        }
        // Its size read from its header and checked against the photo limit and the budget before
        // decoding (io/image_io.h): a small PNG may decode to gigabytes.
        cv::Mat rgb;
        try {
          const ImageHeader header = ReadImageHeader(reinterpret_cast<const uint8_t*>(request.body.data()),
                                                     request.body.size(), "the photo");
          const int64_t pixels = int64_t{header.width} * header.height;
          if (pixels > state.options.max_photo_pixels) {
            return SendError(
                response, 413,
                fmt::format("the photo is {} x {} px ({:.1f} Mpx), more than the {:.1f} Mpx "
                            "this server accepts",
                            header.width, header.height, pixels / 1e6, state.options.max_photo_pixels / 1e6));
          }
          rgb = DecodeImage(reinterpret_cast<const uint8_t*>(request.body.data()), request.body.size(),
                            "the photo", /*color=*/true);
        } catch (const InputError& error) {
          return SendError(response, 422, error.what());
        }
        std::lock_guard lock(document->mutex);
        cv::Mat* slot = PhotoSlot(*document, request, response);
        if (!slot) return;
        *slot = rgb;
        SendJson(response, ToJson(PhotoReply{rgb.cols, rgb.rows, std::nullopt}));
      });
  // A photo the scan's E57 file carries (images2D; GET /api/docs/ID's "e57_images") as the photo to recolour
  // from or the second one: body {"image": K}, ?slot= as for an upload.
  PostDocument(state, R"(/api/docs/(\d+)/photo-from-e57)",
               [](State&, const std::shared_ptr<Document>& document, const nlohmann::json& body,
                  httplib::Response& response) {
                 if (!body.contains("image") || !body["image"].is_number_integer())
                   throw OptionsFieldError("image", "expected the index of one of the scan's E57 photos");
                 const int64_t index = body["image"].get<int64_t>();
                 std::lock_guard lock(document->mutex);
                 if (index < 0 || index >= static_cast<int64_t>(document->e57_images.size())) {
                   throw OptionsFieldError("image",
                                           fmt::format("the scan's E57 file has {} photo(s); {} is none",
                                                       document->e57_images.size(), index));
                 }
                 const E57Image& image = document->e57_images[index];
                 if (image.image.empty()) {
                   return SendError(response, 422,
                                    fmt::format("the E57 photo '{}' does not decode: {}",
                                                Excerpt(image.name, 100), image.decode_error));
                 }
                 httplib::Request slot_request;  // the slot comes in the body here
                 slot_request.params.emplace("slot", body.value("slot", std::string("a")));
                 cv::Mat* slot = PhotoSlot(*document, slot_request, response);
                 if (!slot) return;
                 *slot = image.image;  // shared, never written: a photo slot is replaced, not edited
                 SendJson(response, ToJson(PhotoReply{slot->cols, slot->rows, image.name}));
               });
  http.Get(R"(/api/docs/(\d+)/photo.png)",
           [&state](const httplib::Request& request, httplib::Response& response) {
             auto document = state.FindDocument(request, response);
             if (!document) return;
             std::lock_guard lock(document->mutex);
             const cv::Mat* slot = PhotoSlot(*document, request, response);
             if (!slot) return;
             if (slot->empty()) return SendError(response, 404, "no photo uploaded there for this scan");
             SendPng(response, *slot);
           });
  PostDocument(state, R"(/api/docs/(\d+)/recolor)", Recolor);
  PostDocument(state, R"(/api/docs/(\d+)/recolor-station)", RecolorStation);
  PostDocument(state, R"(/api/docs/(\d+)/align)", Align);
  PostDocument(state, R"(/api/docs/(\d+)/photo-match)", MatchPhotos);
}

}  // namespace lidarshop::server
