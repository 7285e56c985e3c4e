// The described replies (replies.h) write what the routes wrote by hand before them, byte for byte: the same
// keys in the same order with the same values (the front end and the tests read them), and the generated
// TypeScript names each reply.
#include "replies.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "api_types.h"
#include "lidarshop/util/options.h"
#include "state.h"

namespace lidarshop::server {
namespace {

std::string Dump(const nlohmann::ordered_json& json) {
  return json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

TEST(Replies, WriteTheKeysTheRoutesWroteByHand) {
  EXPECT_EQ(Dump(ToJson(ErrorReply{"no open scan 3"})), R"({"error":"no open scan 3"})");
  EXPECT_EQ(Dump(ToJson(HealthReply{})), Dump({{"ok", true}}));
  EXPECT_EQ(Dump(ToJson(ScenesReply{{"tiny", "parking_lot"}})),
            Dump({{"scenes", std::vector<std::string>{"tiny", "parking_lot"}}}));
  EXPECT_EQ(Dump(ToJson(ClosedReply{7})), Dump({{"closed", 7}}));
  EXPECT_EQ(Dump(ToJson(SavePlanReply{"ply", {"xyz", "rgb"}, {}, ""})),
            Dump({{"format", "ply"},
                  {"channels", std::vector<std::string>{"xyz", "rgb"}},
                  {"dropped", std::vector<std::string>{}},
                  {"refused", ""}}));
  EXPECT_EQ(Dump(ToJson(VersionReply{12})), Dump({{"version", 12}}));
  EXPECT_EQ(
      Dump(ToJson(StrokesReply{3, 0, 41, 17})),
      Dump(
          {{"version", 3}, {"hole_cells", 0}, {"object_stroke_cells", 41}, {"background_stroke_cells", 17}}));
  EXPECT_EQ(Dump(ToJson(PreparedReply{true})), Dump({{"prepared", true}}));
  EXPECT_EQ(Dump(ToJson(PhotoReply{320, 240, std::nullopt})), Dump({{"width_px", 320}, {"height_px", 240}}));
  EXPECT_EQ(Dump(ToJson(PhotoReply{3072, 2048, "pumpVisual"})),
            Dump({{"width_px", 3072}, {"height_px", 2048}, {"name", "pumpVisual"}}));
  EXPECT_EQ(Dump(ToJson(ReviewPointReply{"review", 2, {40, 18}, size_t{30}, size_t{4}})),
            Dump({{"state", "review"},
                  {"review_point", 2},
                  {"target", {40, 18}},
                  {"candidates", size_t{30}},
                  {"clusters", size_t{4}}}));
  EXPECT_EQ(Dump(ToJson(ReviewStoppedReply{})), Dump({{"state", "stopped"}}));
  EXPECT_EQ(Dump(ToJson(ReviewClosedReply{})), Dump({{"closed", true}}));
  EXPECT_EQ(Dump(ToJson(RemovedReply{5, {1, 90, 181}})),
            Dump({{"version", 5}, {"cells", std::vector<int64_t>{1, 90, 181}}}));
  EXPECT_EQ(Dump(ToJson(ModelsReply{{"car:sedan"}, {"/data/a.obj"}})),
            Dump({{"builtin", std::vector<std::string>{"car:sedan"}},
                  {"files", nlohmann::ordered_json::array({"/data/a.obj"})}}));
  // Float sizes widened to double, as the hand-written list of floats was.
  const float x = 1.83f, y = 4.6f, z = 1.45f;
  EXPECT_EQ(Dump(ToJson(ModelReply{2, "car:sedan", size_t{1200}, size_t{2400}, {x, y, z}, {}})),
            Dump({{"id", 2},
                  {"name", "car:sedan"},
                  {"vertices", size_t{1200}},
                  {"triangles", size_t{2400}},
                  {"size_m", {x, y, z}},
                  {"warnings", std::vector<std::string>{}}}));
}

TEST(Replies, RecolorReplyKeepsNoneAsNull) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const RecolorReply reply{12, size_t{14}, 0.5, {0.25, nan}, {1, 0}, 900, 30, 2, 1, "s", {"w"}, 4};
  EXPECT_EQ(Dump(ToJson(reply)), Dump({{"inliers", 12},
                                       {"pairs", size_t{14}},
                                       {"rms_px", 0.5},
                                       {"reprojection_error_px", std::vector<double>{0.25, nan}},
                                       {"inlier", std::vector<uint8_t>{1, 0}},
                                       {"recolored_count", int64_t{900}},
                                       {"hidden", int64_t{30}},
                                       {"uncertain", int64_t{2}},
                                       {"outside_image", int64_t{1}},
                                       {"summary", "s"},
                                       {"warnings", std::vector<std::string>{"w"}},
                                       {"version", 4}}));
}

TEST(Replies, JobStateByName) {
  JobReply job{4, "segment", 1, JobState::kCancelled, "segment", 1, 1, std::nullopt, std::nullopt};
  EXPECT_EQ(
      Dump(ToJson(job)),
      R"({"id":4,"kind":"segment","document":1,"state":"cancelled","label":"segment","done":1,"total":1})");
  job.error = "stopped";
  EXPECT_EQ(Dump(ToJson(job)).substr(Dump(ToJson(job)).size() - 19), R"(,"error":"stopped"})");
}

TEST(Replies, JobResultFollowsAsTheRouteAddedIt) {
  JobReply job{4, "segment", 1, JobState::kDone, "segment", 1, 1, std::nullopt, std::nullopt};
  nlohmann::ordered_json by_hand = ToJson(job);
  const nlohmann::ordered_json result = {{"object_cells", 10}, {"refined", false}};
  by_hand["result"] = result;
  job.result = result;
  EXPECT_EQ(Dump(ToJson(job)), Dump(by_hand));
  EXPECT_EQ(Dump(ToJson(job)).substr(Dump(ToJson(job)).find("\"result\"")),
            R"("result":{"object_cells":10,"refined":false}})");
}

TEST(Replies, NoSiteIsNull) {
  nlohmann::ordered_json by_hand = {
      {"site", 0}, {"name", ""}, {"station", -1}, {"stations", nlohmann::ordered_json::array()}};
  by_hand["site"] = nullptr;
  EXPECT_EQ(Dump(ToJson(SiteReply{})), Dump(by_hand));
  EXPECT_EQ(Dump(ToJson(SiteReply{})), R"({"site":null,"name":"","station":-1,"stations":[]})");
  EXPECT_EQ(Dump(ToJson(SiteReply{3, "yard", 1, {}})),
            R"({"site":3,"name":"yard","station":1,"stations":[]})");
}

TEST(Replies, FormatsHoldTheLibrarysTable) {
  const std::vector<ScanFormatSummary> formats = SummarizeScanFormats();
  nlohmann::ordered_json by_hand = {{"read", {"ptx", "las"}}, {"write", {"ptx"}}};
  by_hand["formats"] = nlohmann::ordered_json::array();
  for (const ScanFormatSummary& format : formats) by_hand["formats"].push_back(ToJson(format));
  EXPECT_EQ(Dump(ToJson(FormatsReply{{"ptx", "las"}, {"ptx"}, formats})), Dump(by_hand));
  // A channel is false, true or the format's own name for it.
  const nlohmann::ordered_json reply = ToJson(FormatsReply{{}, {}, formats});
  EXPECT_EQ(reply["formats"][0]["extension"], "ptx");
  EXPECT_EQ(reply["formats"][0]["label"], false);
}

TEST(Replies, JoinedKeepsTheResultsKeysFirstAndRefusesAKeyTwice) {
  const nlohmann::ordered_json result = {{"object_cells", 10}, {"warnings", nlohmann::ordered_json::array()}};
  EXPECT_EQ(Dump(Joined(result, ToJson(SegmentReply{true, false, 3}))),
            R"({"object_cells":10,"warnings":[],"refined":true,"prepared":false,"version":3})");
  EXPECT_THROW(Joined(ToJson(VersionReply{1}), ToJson(VersionReply{2})), std::logic_error);
}

TEST(Replies, ListsOfEntriesAsTheRoutesWroteThem) {
  const FilesReply files{{"/data"},
                         {{"/data/a.ptx", uint64_t{120}, true, std::nullopt},
                          {"/data/b.ptx", uint64_t{12}, false, "b.ptx: not a PTX file"}}};
  EXPECT_EQ(Dump(ToJson(files)),
            R"({"roots":["/data"],"files":[{"path":"/data/a.ptx","bytes":120,"readable":true},)"
            R"({"path":"/data/b.ptx","bytes":12,"readable":false,"error":"b.ptx: not a PTX file"}]})");
  const TilesReply tiles{4, 603, 901, 256, {{0, 603, 901, 4, 3}, {1, 302, 451, 2, 2}}, {0, 0, 0, 0}};
  EXPECT_EQ(Dump(ToJson(tiles)),
            R"({"version":4,"rows":603,"cols":901,"tile_px":256,"levels":[{"level":0,"rows":603,"cols":901,)"
            R"("tiles_x":4,"tiles_y":3},{"level":1,"rows":302,"cols":451,"tiles_x":2,"tiles_y":2}],)"
            R"("changed":[0,0,0,0]})");
  // A station: its version and removed cells only while its document is open; a clean's station: why only
  // when it did not change, before its version.
  StationEntry station{1,     "s1",  {1.0, 2.5, 0.0}, 30.0,        std::vector<double>(16, 0.0),
                       10,    20,    int64_t{150},    true,        3,
                       false, false, std::nullopt,    std::nullopt};
  EXPECT_EQ(Dump(ToJson(station)).find("version"), std::string::npos);
  station.version = 2;
  station.removed_cells = 0;
  EXPECT_EQ(Dump(ToJson(station)).substr(Dump(ToJson(station)).find("\"document\"")),
            R"("document":3,"open":false,"current":false,"version":2,"removed_cells":0})");
  const CleanStationEntry cleaned{0, 3, 10, 12, 9, 10, false, "nothing moved here", 5};
  EXPECT_EQ(Dump(ToJson(cleaned)),
            R"({"station":0,"document":3,"removed":10,"seen_through":12,"confirmed":9,"filled":10,)"
            R"("changed":false,"why":"nothing moved here","version":5})");
  const PendingReviewReply review{"review",
                                  "color",
                                  60,
                                  90,
                                  int64_t{336},
                                  {{{40, 10}, {30, 60}}},
                                  ReviewDetail{0,
                                               7,
                                               {40, 18},
                                               4,
                                               {{uint64_t{0},
                                                 {30, 60},
                                                 std::numeric_limits<double>::infinity(),
                                                 0,
                                                 false,
                                                 "mean",
                                                 0.5,
                                                 0.25,
                                                 -1.0}},
                                               {{uint64_t{0}, 0, {uint64_t{0}}}}}};
  EXPECT_EQ(
      Dump(ToJson(review)),
      R"({"state":"review","channel":"color","rows":60,"cols":90,"hole_cells":336,)"
      R"("decisions":[{"target":[40,10],"source":[30,60]}],"review":{"review_point":0,"iteration":7,)"
      R"("target":[40,18],"patch_radius":4,"candidates":[{"index":0,"source":[30,60],"difference":null,)"
      R"("cluster":0,"accepted":false,"test":"mean","value":0.5,"threshold":0.25,"margin":-1.0}],)"
      R"("clusters":[{"index":0,"representative":0,"members":[0]}]}})");
}

TEST(Replies, AreInTheGeneratedTypeScript) {
  const std::string text = ApiTypesTypeScript();
  for (const char* name :
       {"ErrorReply", "JobReply", "StrokesReply", "SegmentReply", "RecolorReply", "ModelReply"})
    EXPECT_NE(text.find(fmt::format("export interface {} {{", name)), std::string::npos) << name;
  EXPECT_NE(text.find("state: 'queued' | 'running' | 'done' | 'failed' | 'cancelled';"), std::string::npos);
  EXPECT_NE(text.find("  error?: string;"), std::string::npos);
}

}  // namespace
}  // namespace lidarshop::server
