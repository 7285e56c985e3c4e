// The ray image as a tile pyramid (docs/api.md "Tiles"), so that the editor shows a large scan from the few
// tiles its view needs at the level its zoom needs, instead of one PNG of the whole picture (8 Mpx of a 5.4 M-
// return station took 3.2 s to encode; a 100 M-ray one would not fit a browser's canvas at all).
//
// Level 0 is the picture at full resolution (one pixel per ray); level L halves L times, each pixel the mean of
// a 2^L x 2^L block of level 0 (the last row and column of blocks padded by repeating the picture's edge), so a
// tile depends on its footprint at level 0 alone. The picture itself is rendered whole, once per kept state and
// channel (pictures.cc): the colour maps' quantiles are the whole scan's. Tiles are encoded lazily, when asked;
// after an edit a tile is encoded again only when the changed box of the two states' pictures meets its
// footprint — the others are the same bytes, re-stamped.
#include <algorithm>
#include <cstdlib>
#include <vector>

#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "http.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/render/render.h"
#include "lidarshop/util/enum_names.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "replies.h"
#include "version_param.h"

namespace lidarshop::server {

namespace {

int CeilDiv(int a, int b) { return (a + b - 1) / b; }

// The level-0 pixels of tile (tx, ty) of `level` (empty when it lies outside the picture).
cv::Rect Footprint(int rows, int cols, int level, int tx, int ty) {
  const int64_t span = int64_t{kTilePixels} << level;
  const int64_t x0 = tx * span, y0 = ty * span;
  if (x0 >= cols || y0 >= rows) return {};
  return cv::Rect(static_cast<int>(x0), static_cast<int>(y0),
                  static_cast<int>(std::min<int64_t>(span, cols - x0)),
                  static_cast<int>(std::min<int64_t>(span, rows - y0)));
}

// The box of level-0 pixels that differ between the pictures of states `from` and `to` (kept by the three keys;
// entries of states no longer kept are dropped). The whole picture when the grid changed.
cv::Rect ChangedBetween(Document& document, const RenderOptions& options, const std::string& channel,
                        const Document::PointState& from, const Document::PointState& to) {
  const Scan& a = from.points.scan;
  const Scan& b = to.points.scan;
  if (a.rows != b.rows || a.cols != b.cols) return cv::Rect(0, 0, b.cols, b.rows);
  if (&from == &to || SameScanBuffers(a, b)) return {};  // a stroke, a cut: no pixel moved
  auto& cache = document.changed_boxes;
  const auto key = std::make_tuple(channel, from.first_version, to.first_version);
  if (const auto found = cache.find(key); found != cache.end()) return found->second;
  const auto kept = [&](int64_t first) {
    return std::any_of(document.recent.begin(), document.recent.end(),
                       [&](const auto& s) { return s.first_version == first; });
  };
  for (auto it = cache.begin(); it != cache.end();) {
    it = kept(std::get<1>(it->first)) && kept(std::get<2>(it->first)) ? std::next(it) : cache.erase(it);
  }
  const cv::Mat before = Picture(document, from, options, channel);
  const cv::Mat after = Picture(document, to, options, channel);
  return cache[key] = ChangedBox(before, after);
}

const Document::PointState* StateWithFirstVersion(const Document& document, int64_t first) {
  for (const auto& state : document.recent) {
    if (state.first_version == first) return &state;
  }
  return nullptr;
}

// Means of `factor` x `factor` blocks of `image` (INTER_AREA at an integer factor is exactly that), the last
// column and row of blocks completed by repeating the image's own edge (not pixels of a picture it is a region
// of: BORDER_ISOLATED). The whole blocks are averaged in place and
// only the edge strips are padded: the coarsest tile of a 100 M-ray station is the whole 300 MB picture, and a
// padded copy of it was 29 % of the request (perf, the intensity channel).
cv::Mat BlockMeans(const cv::Mat& image, int factor) {
  const int whole_cols = image.cols / factor, whole_rows = image.rows / factor;
  const int cols = CeilDiv(image.cols, factor), rows = CeilDiv(image.rows, factor);
  cv::Mat means(rows, cols, image.type());
  // The blocks of `part` (image pixels) into `out` (block cells), padded up to whole blocks.
  auto average = [&](const cv::Rect& part, const cv::Rect& out) {
    if (out.empty()) return;
    cv::Mat source = image(part), padded, result;
    if (part.width != out.width * factor || part.height != out.height * factor) {
      cv::copyMakeBorder(source, padded, 0, out.height * factor - part.height, 0,
                         out.width * factor - part.width, cv::BORDER_REPLICATE | cv::BORDER_ISOLATED);
      source = padded;
    }
    cv::resize(source, result, out.size(), 0, 0, cv::INTER_AREA);
    result.copyTo(means(out));
  };
  const int x = whole_cols * factor, y = whole_rows * factor;
  average({0, 0, x, y}, {0, 0, whole_cols, whole_rows});
  average({x, 0, image.cols - x, y}, {whole_cols, 0, cols - whole_cols, whole_rows});
  average({0, y, x, image.rows - y}, {0, whole_rows, whole_cols, rows - whole_rows});
  average({x, y, image.cols - x, image.rows - y},
          {whole_cols, whole_rows, cols - whole_cols, rows - whole_rows});
  return means;
}

// The tile's pixels as PNG: the footprint's block means.
std::string RenderTile(const cv::Mat& picture, int level, const cv::Rect& footprint) {
  cv::Mat tile = picture(footprint);
  if (level > 0) tile = BlockMeans(tile, 1 << level);
  cv::Mat bgr;
  cv::cvtColor(tile, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> png;
  CvImEncode(".png", bgr, &png);
  return std::string(png.begin(), png.end());
}

// Drops the least recently used tiles until the cache holds at most 3/4 of kMaxTileCacheBytes.
void TrimTiles(Document& document) {
  if (document.tile_bytes <= kMaxTileCacheBytes) return;
  std::vector<std::pair<int64_t, decltype(document.tiles)::iterator>> by_use;
  for (auto it = document.tiles.begin(); it != document.tiles.end(); ++it)
    by_use.emplace_back(it->second.used, it);
  std::sort(by_use.begin(), by_use.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [used, it] : by_use) {
    if (document.tile_bytes <= kMaxTileCacheBytes / 4 * 3) break;
    document.tile_bytes -= static_cast<int64_t>(it->second.png.size());
    document.tiles.erase(it);
  }
}

// A whole number of at most 9 digits from a path match, else -1 (a coordinate no picture has).
int Coordinate(const std::string& text) {
  if (text.empty() || text.size() > 9) return -1;
  return std::atoi(text.c_str());
}

}  // namespace

int TileLevels(int rows, int cols) {
  int level = 0;
  while ((int64_t{kTilePixels} << level) < std::max(rows, cols)) ++level;
  return level;
}

nlohmann::ordered_json TilesInfo(Document& document, const RenderOptions& options, const std::string& channel,
                                 int64_t since) {
  const Document::PointState& now = document.recent.back();
  const int rows = now.points.scan.rows, cols = now.points.scan.cols;
  std::vector<TileLevelEntry> levels;
  for (int level = 0; level <= TileLevels(rows, cols); ++level) {
    const int level_rows = CeilDiv(rows, 1 << level), level_cols = CeilDiv(cols, 1 << level);
    levels.push_back(
        {level, level_rows, level_cols, CeilDiv(level_cols, kTilePixels), CeilDiv(level_rows, kTilePixels)});
  }
  cv::Rect changed(0, 0, cols, rows);
  if (since >= 0) {
    if (const Document::PointState* old = StateAt(document, since)) {
      changed = ChangedBetween(document, options, channel, *old, now);
    }
  }
  return ToJson(TilesReply{document.version,
                           rows,
                           cols,
                           kTilePixels,
                           std::move(levels),
                           {changed.x, changed.y, changed.width, changed.height}});
}

void SendTile(Document& document, const RenderOptions& options, const std::string& channel, int level, int tx,
              int ty, httplib::Response& response) {
  const Document::PointState& now = document.recent.back();  // RememberState runs on every version change
  const int rows = now.points.scan.rows, cols = now.points.scan.cols;
  const cv::Rect footprint = level < 0 || level > TileLevels(rows, cols) || tx < 0 || ty < 0
                                 ? cv::Rect()
                                 : Footprint(rows, cols, level, tx, ty);
  if (footprint.empty()) {
    return SendError(response, 404,
                     fmt::format("no tile ({}, {}) at level {} of a {} x {} picture (levels 0 to {})", tx, ty,
                                 level, cols, rows, TileLevels(rows, cols)));
  }
  response.set_header("X-Lidarshop-Version", std::to_string(document.version));
  Document::Tile& tile = document.tiles[std::make_tuple(channel, level, tx, ty)];
  tile.used = ++document.tile_uses;
  if (tile.state != now.first_version) {
    const Document::PointState* old = tile.state >= 0 ? StateWithFirstVersion(document, tile.state) : nullptr;
    if (old != nullptr && (ChangedBetween(document, options, channel, *old, now) & footprint).empty()) {
      // Untouched by the edits since: the same pixels. The tile keeps the version of its render.
    } else {
      document.tile_bytes -= static_cast<int64_t>(tile.png.size());
      tile.png = RenderTile(Picture(document, now, options, channel), level, footprint);
      document.tile_bytes += static_cast<int64_t>(tile.png.size());
      tile.state = now.first_version;
    }
  }
  response.set_header("X-Lidarshop-Tile-Version", std::to_string(tile.state));
  response.set_content(tile.png, "image/png");
  TrimTiles(document);  // after copying the answer: `tile` may be dropped
}

void AddTileRoutes(State& state) {
  // The channel of a picture request (?channel=, range by default) parsed into `options`; false after a 400.
  const auto channel_of = [](const httplib::Request& request, RenderOptions& options, std::string& channel,
                             httplib::Response& response) {
    channel = request.has_param("channel") ? request.get_param_value("channel") : "range";
    try {
      options.channel = ParseEnum<RenderChannel>(channel);
    } catch (const OptionsError& error) {
      SendError(response, 400, error.what());
      return false;
    }
    return true;
  };
  state.http.Get(R"(/api/docs/(\d+)/tiles\.json)",
                 [&state, channel_of](const httplib::Request& request, httplib::Response& response) {
                   auto document = state.FindDocument(request, response);
                   if (!document) return;
                   RenderOptions options;
                   std::string channel;
                   if (!channel_of(request, options, channel, response)) return;
                   int64_t since = -1;
                   if (!ReadSinceParam(request, response, &since)) return;
                   try {
                     std::lock_guard lock(document->mutex);
                     SendJson(response, TilesInfo(*document, options, channel, since));
                   } catch (const InputError& error) {
                     SendError(response, 422, error.what());  // e.g. rgb of a scan without colour
                   }
                 });
  state.http.Get(R"(/api/docs/(\d+)/tiles/(\d+)/(\d+)/(\d+)\.png)",
                 [&state, channel_of](const httplib::Request& request, httplib::Response& response) {
                   auto document = state.FindDocument(request, response);
                   if (!document) return;
                   RenderOptions options;
                   std::string channel;
                   if (!channel_of(request, options, channel, response)) return;
                   const int level = Coordinate(request.matches[2].str());
                   const int tx = Coordinate(request.matches[3].str());
                   const int ty = Coordinate(request.matches[4].str());
                   try {
                     std::lock_guard lock(document->mutex);
                     SendTile(*document, options, channel, level, tx, ty, response);
                   } catch (const InputError& error) {
                     SendError(response, 422, error.what());
                   }
                 });
}

}  // namespace lidarshop::server
