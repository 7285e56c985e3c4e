#include "lidarshop/cli/inpaint_review.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/image_io.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop::cli {

using nlohmann::json;

namespace {

Pixel JsonPixel(const json& j, const std::string& file, const std::string& field) {
  if (!j.is_array() || j.size() != 2 || !j[0].is_number_integer() || !j[1].is_number_integer())
    ThrowInputError(file, "", field, "expected [row, col]");
  return {j[0].get<int>(), j[1].get<int>()};
}

}  // namespace

void WriteReviewFolder(const std::string& dir, const InpaintReview& review,
                       const std::vector<ReviewDecision>& decisions, const cv::Mat& tentative_display,
                       const cv::Mat& canvas_display, int patch_radius) {
  std::filesystem::create_directories(dir);
  const ReviewFolderSummary doc{SummarizeDecisions(decisions), SummarizeReview(review, patch_radius)};
  WriteFileAtomically(dir + "/review.json", [&](std::ostream& out) { out << ToJson(doc).dump(1) << "\n"; });

  const int R = patch_radius, w = 2 * R + 1;
  cv::Mat tentative = tentative_display.clone();
  cv::rectangle(tentative, cv::Rect(review.target.col - R - 1, review.target.row - R - 1, w + 2, w + 2),
                cv::Scalar::all(255), 1);
  WriteImage(dir + "/tentative.png", tentative);
  // One tile per cluster (the representative's source patch, 4x), 10 tiles per row, 2-pixel gaps.
  const int tile = 4 * w, per_row = 10, n = static_cast<int>(review.cluster_representative.size());
  const int rows = std::max(1, (n + per_row - 1) / per_row);
  cv::Mat sheet(rows * (tile + 2), per_row * (tile + 2), canvas_display.type(), cv::Scalar::all(0));
  for (int c = 0; c < n; ++c) {
    const Pixel s = review.candidates[review.cluster_representative[c]].source;
    cv::Mat patch;
    cv::resize(canvas_display(cv::Rect(s.col - R, s.row - R, w, w)), patch, cv::Size(tile, tile), 0, 0,
               cv::INTER_NEAREST);
    patch.copyTo(sheet(cv::Rect((c % per_row) * (tile + 2), (c / per_row) * (tile + 2), tile, tile)));
  }
  WriteImage(dir + "/clusters.png", sheet);
}

ReviewFolder ReadReviewFolder(const std::string& dir) {
  const std::string file = dir + "/review.json";
  std::ifstream in(file);
  if (!in) ThrowInputError(file, "", "", "cannot open (run inpaint with --review first)");
  json doc;
  try {
    doc = json::parse(in);
  } catch (const json::exception& e) {
    ThrowInputError(file, "", "", e.what());
  }
  ReviewFolder folder;
  if (!doc.contains("decisions") || !doc["decisions"].is_array())
    ThrowInputError(file, "", "decisions", "missing");
  for (size_t i = 0; i < doc["decisions"].size(); ++i) {
    const json& d = doc["decisions"][i];
    const std::string field = fmt::format("decisions[{}]", i);
    folder.decisions.push_back({JsonPixel(d.value("target", json()), file, field + ".target"),
                                JsonPixel(d.value("source", json()), file, field + ".source")});
  }
  if (!doc.contains("review") || !doc["review"].is_object())
    ThrowInputError(file, "", "review", "missing: the fill in this folder is complete");
  const json& r = doc["review"];
  folder.target = JsonPixel(r.value("target", json()), file, "review.target");
  const json candidates = r.value("candidates", json::array());
  for (size_t i = 0; i < candidates.size(); ++i)
    folder.candidates.push_back(
        JsonPixel(candidates[i].value("source", json()), file, fmt::format("review.candidates[{}]", i)));
  return folder;
}

}  // namespace lidarshop::cli
