// Pictures that travel by what changed (docs/api.md "Pictures"): the ray image as the box of pixels that differ
// from the picture a client holds, and overlays cropped to the box of their drawn pixels, so that an edit of a
// large scan does not send (nor encode) its whole ray image again.
#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "http.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/render/render.h"

namespace lidarshop::server {

// The point state kept for `version` (Document::recent), or nullptr when it is no longer kept.
const Document::PointState* StateAt(const Document& document, int64_t version) {
  for (const auto& state : document.recent) {
    if (state.first_version <= version && version <= state.last_version) return &state;
  }
  return nullptr;
}

bool SameScanBuffers(const Scan& a, const Scan& b) {
  const auto same = [](const cv::Mat& m, const cv::Mat& n) { return m.data == n.data && m.size == n.size; };
  return same(a.valid, b.valid) && same(a.range, b.range) && same(a.point, b.point) &&
         same(a.color, b.color) && same(a.intensity, b.intensity) && same(a.label, b.label) &&
         same(a.synthesized, b.synthesized) && same(a.normal, b.normal);
}

// Entries of states no longer kept are dropped.
cv::Mat Picture(Document& document, const Document::PointState& state, const RenderOptions& options,
                const std::string& channel) {
  auto& cache = document.pictures;
  const auto key = std::make_pair(channel, state.first_version);
  if (const auto found = cache.find(key); found != cache.end()) return found->second;
  for (auto it = cache.begin(); it != cache.end();) {
    const bool kept = std::any_of(document.recent.begin(), document.recent.end(),
                                  [&](const auto& s) { return s.first_version == it->first.second; });
    it = kept ? std::next(it) : cache.erase(it);
  }
  cv::Mat image = RenderScan(state.points.scan, options).image;
  cache[key] = image;
  return image;
}

cv::Rect ChangedBox(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  if (difference.channels() > 1) difference = difference.reshape(1, difference.rows * difference.cols);
  cv::Mat any;
  if (difference.cols > 1) {
    cv::reduce(difference, any, 1, cv::REDUCE_MAX);
  } else {
    any = difference;
  }
  any = any.reshape(1, a.rows);
  return cv::boundingRect(any);
}

void SetBoxHeader(httplib::Response& response, const cv::Rect& box) {
  response.set_header("X-Lidarshop-Box", fmt::format("{},{},{},{}", box.x, box.y, box.width, box.height));
}

namespace {

void SetBox(httplib::Response& response, const cv::Rect& box, const cv::Size& size) {
  SetBoxHeader(response, box);
  response.set_header("X-Lidarshop-Size", fmt::format("{},{}", size.width, size.height));
}

}  // namespace

void SendRayPicture(Document& document, const RenderOptions& options, const std::string& channel,
                    int64_t since, httplib::Response& response) {
  response.set_header("X-Lidarshop-Version", std::to_string(document.version));
  const Document::PointState& now = document.recent.back();  // RememberState runs on every version change
  const Document::PointState* old = since >= 0 ? StateAt(document, since) : nullptr;
  if (old == nullptr || old->points.scan.rows != now.points.scan.rows ||
      old->points.scan.cols != now.points.scan.cols) {
    return SendPng(response, Picture(document, now, options, channel));
  }
  const cv::Size size(now.points.scan.cols, now.points.scan.rows);
  if (old == &now || SameScanBuffers(old->points.scan, now.points.scan)) {  // a stroke, a cut: no pixel moved
    SetBox(response, cv::Rect(), size);
    return response.set_content(std::string(), "image/png");
  }
  const cv::Mat before = Picture(document, *old, options, channel);
  const cv::Mat after = Picture(document, now, options, channel);
  const cv::Rect box = ChangedBox(before, after);
  SetBox(response, box, size);
  if (box.empty()) return response.set_content(std::string(), "image/png");
  SendPng(response, after(box));
}

void SendOverlay(httplib::Response& response, const cv::Mat& bgra, const cv::Rect* box, cv::Size size) {
  if (box != nullptr) {
    SetBox(response, *box, size);
    if (box->empty()) return response.set_content(std::string(), "image/png");
  }
  std::vector<uint8_t> png;
  CvImEncode(".png", bgra, &png);
  response.set_content(std::string(png.begin(), png.end()), "image/png");
}

}  // namespace lidarshop::server
