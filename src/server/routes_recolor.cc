// Routes that recolour a scan from a photo (recolor/, thesis 3.2): upload the photo, pick pixel <-> cell pairs,
// resection the camera and project the photo's colours onto the points it sees (docs/api.md).
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "http.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop::server {

namespace {

// One pair {"pixel": [x, y], "cell": [row, col]} as a pixel and the cell's point in the world frame.
PixelPointPair PairOf(const nlohmann::json& pair, const Scan& scan, const cv::Mat& photo, size_t index) {
  const std::string key = fmt::format("pairs[{}]", index);
  if (!pair.is_object() || !pair.contains("pixel") || !pair.contains("cell") || pair["pixel"].size() != 2 ||
      pair["cell"].size() != 2 || !pair["pixel"][0].is_number() || !pair["pixel"][1].is_number() ||
      !pair["cell"][0].is_number_integer() || !pair["cell"][1].is_number_integer()) {
    throw OptionsFieldError(key, "expected {\"pixel\": [x, y], \"cell\": [row, col]}");
  }
  const double x = pair["pixel"][0], y = pair["pixel"][1];
  const int row = pair["cell"][0], col = pair["cell"][1];
  if (!(x >= 0 && y >= 0 && x < photo.cols && y < photo.rows)) {
    throw OptionsFieldError(
        key, fmt::format("pixel ({}, {}) is outside the {} x {} photo", x, y, photo.cols, photo.rows));
  }
  if (row < 0 || col < 0 || row >= scan.rows || col >= scan.cols || scan.valid.at<uint8_t>(row, col) == 0) {
    throw OptionsFieldError(key, fmt::format("cell [{}, {}] has no return", row, col));
  }
  const cv::Vec3f p = scan.point.at<cv::Vec3f>(row, col);
  const Eigen::Vector4d world = scan.world_from_scanner * Eigen::Vector4d(p[0], p[1], p[2], 1.0);
  return {Eigen::Vector2d(x, y), world.head<3>()};
}

}  // namespace

void AddRecolorRoutes(State& state) {
  httplib::Server& http = state.http;
  // The photo as the request body (PNG or JPEG bytes); kept with the document.
  http.Post(R"(/api/docs/(\d+)/photo)",
            [&state](const httplib::Request& request, httplib::Response& response) {
              auto document = state.FindDocument(request, response);
              if (!document) return;
              const std::vector<uint8_t> bytes(request.body.begin(), request.body.end());
              cv::Mat decoded;
              try {
                decoded = cv::imdecode(bytes, cv::IMREAD_COLOR);
              } catch (const cv::Exception& error) {
                return SendError(response, 422, fmt::format("the photo does not decode: {}", error.err));
              }
              if (decoded.empty()) return SendError(response, 422, "the photo is not a PNG or JPEG image");
              cv::Mat rgb;
              cv::cvtColor(decoded, rgb, cv::COLOR_BGR2RGB);
              std::lock_guard lock(document->mutex);
              document->photo = rgb;
              SendJson(response, {{"width_px", rgb.cols}, {"height_px", rgb.rows}});
            });
  http.Get(R"(/api/docs/(\d+)/photo.png)",
           [&state](const httplib::Request& request, httplib::Response& response) {
             auto document = state.FindDocument(request, response);
             if (!document) return;
             std::lock_guard lock(document->mutex);
             if (document->photo.empty()) return SendError(response, 404, "no photo uploaded for this scan");
             cv::Mat bgr;
             cv::cvtColor(document->photo, bgr, cv::COLOR_RGB2BGR);
             std::vector<uint8_t> png;
             cv::imencode(".png", bgr, png);
             response.set_content(std::string(png.begin(), png.end()), "image/png");
           });
  // Resection from the pairs, then occlusion-aware recolouring; an undoable edit (a job).
  http.Post(R"(/api/docs/(\d+)/recolor)", [&state](const httplib::Request& request,
                                                   httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    const auto body = BodyJson(request, response);
    if (!body) return;
    try {
      std::vector<PixelPointPair> pairs;
      ResectionOptions resection;
      {
        std::lock_guard lock(document->mutex);
        if (document->photo.empty()) return SendError(response, 400, "upload a photo first (POST .../photo)");
        const nlohmann::json list = body->value("pairs", nlohmann::json::array());
        if (!list.is_array() || list.size() > 10000)
          throw OptionsFieldError("pairs", "expected a list of pairs");
        for (size_t i = 0; i < list.size(); ++i)
          pairs.push_back(PairOf(list[i], document->now.scan, document->photo, i));
        resection.width_px = document->photo.cols;
        resection.height_px = document->photo.rows;
      }
      CheckResectionInput(pairs, resection.degenerate_ratio, "pairs");
      const int undo_depth = state.options.undo_depth;
      auto job = std::make_shared<Job>();
      job->id = state.runner->NextId();
      job->document = document->id;
      job->kind = "recolor";
      job->run = [document, pairs, resection, undo_depth](Progress& progress) {
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
        const RecolorResult recolored = RecolorScan(start.scan, photo, camera.camera);
        progress.Advance();
        std::lock_guard lock(document->mutex);
        Snapshot next = document->now;
        next.scan = recolored.scan;
        document->undo.push_back(std::move(document->now));
        if (static_cast<int>(document->undo.size()) > undo_depth)
          document->undo.erase(document->undo.begin());
        document->redo.clear();
        document->now = std::move(next);
        ++document->version;
        return nlohmann::ordered_json{{"inliers", camera.num_inliers},
                                      {"pairs", pairs.size()},
                                      {"rms_px", camera.rms_px},
                                      {"reprojection_error_px", camera.reprojection_error_px},
                                      {"recolored_count", recolored.recolored_count},
                                      {"hidden", recolored.hidden},
                                      {"outside_image", recolored.outside_image},
                                      {"summary", camera.Summary() + "; " + recolored.Summary()},
                                      {"version", document->version}};
      };
      if (!state.runner->Submit(job))
        return SendError(response, 503, "too many operations queued; try again");
      SendJson(response,
               {{"id", job->id}, {"kind", job->kind}, {"document", job->document}, {"state", "queued"}}, 202);
    } catch (const OptionsError& error) {
      SendError(response, 400, error.what());
    } catch (const InputError& error) {
      SendError(response, 400, error.what());  // pairs that cannot determine a camera
    }
  });
}

}  // namespace lidarshop::server
