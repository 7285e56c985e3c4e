// Routes of a site's stations (docs/api.md "Stations", docs/stations.md "In the editor"): a file of several
// scans (or a built-in site) opened as one document per station grouped in a site, open documents grouped
// into one, a document's stations listed with where they stand, and Clean (site/transients.h CleanStations)
// over the site as one undoable edit per station. The library does the work (site/site_stations.h,
// site/transients.h); this file parses, checks and answers.
#include <algorithm>
#include <filesystem>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "http.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/site/from_stations.h"
#include "lidarshop/site/site_stations.h"
#include "lidarshop/site/transients.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "replies.h"

namespace lidarshop::server {

namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxGroupedDocuments = 1024;

// The site document `id` is a station of (the latest that lists it) and its station index; {null, -1} when
// it is in none.
std::pair<std::shared_ptr<Site>, int> SiteOf(State& state, int id) {
  std::lock_guard lock(state.documents_mutex);
  for (auto it = state.sites.rbegin(); it != state.sites.rend(); ++it) {
    const std::vector<int>& documents = it->second->documents;
    const auto found = std::find(documents.begin(), documents.end(), id);
    if (found != documents.end()) return {it->second, static_cast<int>(found - documents.begin())};
  }
  return {nullptr, -1};
}

// The open document `id`, or null when it was closed.
std::shared_ptr<Document> OpenDocumentOf(State& state, int id) {
  std::lock_guard lock(state.documents_mutex);
  const auto found = state.documents.find(id);
  return found == state.documents.end() ? nullptr : found->second;
}

std::shared_ptr<Site> AddSite(State& state, std::string name, std::vector<int> documents,
                              std::vector<StationSummary> stations) {
  auto site = std::make_shared<Site>();
  site->name = std::move(name);
  site->documents = std::move(documents);
  site->stations = std::move(stations);
  std::lock_guard lock(state.documents_mutex);
  site->id = ++state.last_site;
  state.sites[site->id] = site;
  return site;
}

// The site as the routes answer it: "station" is the index of `current_document` (-1 = none); each station's
// summary (site_stations.h) with its document, and while that is open its version and removed cells.
SiteReply SiteReplyOf(State& state, const Site& site, int current_document) {
  SiteReply reply{site.id, site.name, -1, {}};
  for (size_t i = 0; i < site.documents.size(); ++i) {
    StationSummary summary = site.stations[i];
    const auto document = OpenDocumentOf(state, site.documents[i]);
    int64_t version = -1, removed = 0;
    if (document) {
      std::lock_guard lock(document->mutex);
      summary.returns = document->now.scan.CountValid();
      version = document->version;
      removed = document->now.removed.empty() ? 0 : cv::countNonZero(document->now.removed);
    }
    const Eigen::Matrix4d& pose = summary.world_from_scanner;
    StationEntry entry{summary.index,
                       summary.name,
                       {summary.position_m.x(), summary.position_m.y(), summary.position_m.z()},
                       summary.heading_deg,
                       std::vector<double>(pose.data(), pose.data() + 16),
                       summary.rows,
                       summary.cols,
                       summary.returns,
                       summary.organized,
                       site.documents[i],
                       document != nullptr,
                       site.documents[i] == current_document,
                       std::nullopt,
                       std::nullopt};
    if (document) {
      entry.version = version;
      entry.removed_cells = removed;
    }
    if (site.documents[i] == current_document) reply.station = static_cast<int>(i);
    reply.stations.push_back(std::move(entry));
  }
  return reply;
}

// Opens `scans` as one document each, named `name#i` (or `name` for one); on any failure (too many open, no
// memory) the ones already opened are closed again and the error is rethrown. Returns their ids.
std::vector<int> OpenStations(State& state, const std::string& name, std::vector<Scan> scans,
                              const std::vector<E57Image>& images) {
  std::vector<int> ids;
  try {
    for (size_t i = 0; i < scans.size(); ++i) {
      const std::string document_name = scans.size() == 1 ? name : fmt::format("{}#{}", name, i);
      ids.push_back(state.AddDocument(document_name, std::move(scans[i]), ImagesOfScan(images, int(i))));
    }
  } catch (...) {
    std::lock_guard lock(state.documents_mutex);
    for (const int id : ids) state.documents.erase(id);
    throw;
  }
  return ids;
}

// The whole numbers of `body[key]` (a list), or `fallback` without the key; OptionsFieldError otherwise.
std::vector<int> IntList(const nlohmann::json& body, const char* key, std::vector<int> fallback) {
  if (!body.contains(key)) return fallback;
  const nlohmann::json& list = body.at(key);
  if (!list.is_array()) throw OptionsFieldError(key, "expected a list of whole numbers");
  if (list.size() > kMaxGroupedDocuments)
    throw OptionsFieldError(key, fmt::format("more than {} entries", kMaxGroupedDocuments));
  std::vector<int> values;
  for (const auto& value : list) {
    if (!value.is_number_integer() || value.get<int64_t>() < INT32_MIN || value.get<int64_t>() > INT32_MAX)
      throw OptionsFieldError(key, fmt::format("expected whole numbers, got {}", Excerpt(value.dump(), 40)));
    values.push_back(value.get<int>());
  }
  return values;
}

// POST /api/sites: {"path": FILE} (every scan of a file of several), {"scene": NAME} (every station of a
// built-in scene) or {"documents": [ids], "name": N} (open scans grouped); "station" (0) is the one shown.
void OpenSite(State& state, const nlohmann::json& body, httplib::Response& response) {
  const int station = body.value("station", 0);
  const auto check_station = [station](size_t count) {
    CheckStationIndices({station}, static_cast<int>(count), "station");
  };
  std::vector<int> ids;
  std::vector<StationSummary> summaries;
  std::string name;
  std::vector<std::string> warnings;
  if (body.contains("documents")) {
    ids = IntList(body, "documents", {});
    if (ids.size() < 2) throw OptionsFieldError("documents", "a site groups two open scans or more");
    for (size_t i = 0; i < ids.size(); ++i) {
      if (std::count(ids.begin(), ids.end(), ids[i]) > 1)
        throw OptionsFieldError("documents", fmt::format("scan {} is given twice", ids[i]));
      const auto document = OpenDocumentOf(state, ids[i]);
      if (!document) return SendError(response, 404, fmt::format("no open scan {}", ids[i]));
      std::lock_guard lock(document->mutex);
      summaries.push_back(SummarizeStation(document->now.scan, static_cast<int>(i)));
      summaries.back().name = document->name;
    }
    check_station(ids.size());
    name = body.value("name", fmt::format("site of {} scans", ids.size()));
  } else if (body.contains("scene")) {
    name = body.at("scene").get<std::string>();
    const auto& names = state.options.builtin_scenes;
    if (std::find(names.begin(), names.end(), name) == names.end() || !state.options.scan_builtin)
      return SendError(response, 404, fmt::format("no built-in scene '{}'", Excerpt(name, 100)));
    state.CheckRoomForDocument();  // before scanning it
    std::vector<Scan> scans = state.options.scan_builtin_stations
                                  ? state.options.scan_builtin_stations(name)
                                  : std::vector<Scan>{state.options.scan_builtin(name)};
    check_station(scans.size());
    summaries = SummarizeStations(scans);
    ids = OpenStations(state, name, std::move(scans), {});
  } else if (body.contains("path")) {
    const std::string requested = body.at("path").get<std::string>();
    const std::string path = ResolveUnderRoots(state.options.roots, requested);
    if (path.empty()) {
      return SendError(response, 403,
                       fmt::format("'{}' is not a file under the folders this server was started with",
                                   Excerpt(requested, 200)));
    }
    state.CheckRoomForDocument();  // before reading the file
    FileForEditing opened = ReadFileForEditing(path);
    if (opened.file.scans.empty()) throw InputError(fmt::format("{}: holds no scan", requested));
    check_station(opened.file.scans.size());
    warnings = opened.file.warnings;
    summaries = SummarizeStations(opened.file.scans);
    name = fs::path(path).filename().string();
    ids = OpenStations(state, name, std::move(opened.file.scans), opened.images);
  } else {
    throw OptionsError("expected \"path\", \"scene\" or \"documents\": what the site is made of");
  }
  const auto site = AddSite(state, name, ids, std::move(summaries));
  SendJson(response, Joined(ToJson(SiteReplyOf(state, *site, ids[station])),
                            ToJson(OpenedSiteReply{ids[station], warnings})));
}

// POST /api/docs/ID/clean: {"options": CleanOptions, "stations": [indices] (default: all)}. One job; every
// station's document whose points changed gets one edit (its own undo), a station edited meanwhile is left
// as it is and says so.
void Clean(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
           httplib::Response& response) {
  const CleanOptions options =
      body.contains("options") ? FromJson<CleanOptions>(body.at("options")) : CleanOptions{};
  options.Check();
  // Named variables, not a structured binding: lambdas below capture them (clang 14 refuses bindings).
  const std::pair<std::shared_ptr<Site>, int> site_of = SiteOf(state, document->id);
  const std::shared_ptr<Site>& site = site_of.first;
  const int current = site_of.second;
  if (!site) {
    throw InputError(
        fmt::format("scan {} is not a station of a site: open a file of several scans as a site, or group "
                    "open scans into "
                    "one, then clean",
                    document->id));
  }
  const int num_stations = static_cast<int>(site->documents.size());
  std::vector<int> all(num_stations);
  for (int i = 0; i < num_stations; ++i) all[i] = i;
  const std::vector<int> chosen = IntList(body, "stations", all);
  CheckStationIndices(chosen, num_stations, "stations");
  if (chosen.size() < 2)
    throw OptionsFieldError("stations",
                            fmt::format("clean compares two stations or more, got {}", chosen.size()));
  std::vector<std::shared_ptr<Document>> documents;
  for (const int i : chosen) {
    documents.push_back(OpenDocumentOf(state, site->documents[i]));
    if (!documents.back()) {
      return SendError(response, 409,
                       fmt::format("station {} (scan {}) was closed: open the site again, or leave it out "
                                   "(\"stations\")",
                                   i, site->documents[i]));
    }
  }
  const int undo_depth = state.options.undo_depth;
  const int current_document = document->id;
  StartJob(
      state, document, "clean",
      [documents, chosen, options, undo_depth, current, current_document](Progress& progress) {
        std::vector<Scan> scans;
        std::vector<int64_t> versions;
        for (const auto& station : documents) {
          std::lock_guard lock(station->mutex);
          scans.push_back(station->now.scan);
          versions.push_back(station->version);
        }
        const CleanResult result = CleanStations(scans, options, &progress);
        std::vector<CleanStationEntry> stations;
        int64_t removed_here = 0, version_here = -1;
        for (size_t i = 0; i < documents.size(); ++i) {
          Document& station = *documents[i];
          const StationTransients& found = result.transients.stations[i];
          std::lock_guard lock(station.mutex);
          CleanStationEntry entry{chosen[i],
                                  station.id,
                                  found.transient_cells,
                                  found.seen_through_cells,
                                  found.confirmed_cells,
                                  result.filled_cells[i],
                                  false,
                                  std::nullopt,
                                  0};
          if (station.version != versions[i]) {
            entry.why = "edited while the clean ran: left as it is (clean again)";
          } else if (found.transient_cells == 0) {
            entry.why = "nothing moved here";
          } else {
            Snapshot next = station.now;
            next.scan = result.stations[i];
            next.removed = found.transient.clone();  // a new buffer: see Snapshot
            try {
              Commit(station, std::move(next), undo_depth);
              entry.changed = true;
            } catch (
                const DocumentLimitError& error) {  // past the memory limit: this station stays as it was
              entry.why = error.what();
            }
          }
          entry.version = station.version;
          if (station.id == current_document) {
            removed_here = found.transient_cells;
            version_here = station.version;
          }
          stations.push_back(std::move(entry));
        }
        return ToJson(CleanReply{current, removed_here, version_here, std::move(stations), result.warnings});
      },
      response);
}

// POST /api/docs/ID/fill-from-stations: {"hole": "strokes" (the object cut from the strokes, then removed: as
// `remove`) | "object" (the last cut's cells grown by margin_cells) | "painted", "margin_cells": 2, "stations":
// [K, ...] (default: every other open station of the site), "options": FromStationsOptions, "remove":
// RemoveOptions}. One job, one undoable edit of this scan; the cells filled from another station are marked
// (Scan::from_station) and drawn as their own layer, the rest synthesized.
void FillFromOtherStations(State& state, const std::shared_ptr<Document>& document,
                           const nlohmann::json& body, httplib::Response& response) {
  const FromStationsOptions options =
      body.contains("options") ? FromJson<FromStationsOptions>(body.at("options")) : FromStationsOptions{};
  options.Check();
  const RemoveOptions remove =
      body.contains("remove") ? FromJson<RemoveOptions>(body.at("remove")) : RemoveOptions{};
  remove.Check();
  const std::string which = body.value("hole", std::string("strokes"));
  if (which != "strokes" && which != "object" && which != "painted")
    throw OptionsFieldError("hole", "expected \"strokes\", \"object\" or \"painted\"");
  const int margin = body.value("margin_cells", 2);
  if (margin < 0 || margin > 100) throw OptionsFieldError("margin_cells", "out of range [0, 100]");
  // Named variables, not a structured binding: lambdas below capture them (clang 14 refuses bindings).
  const std::pair<std::shared_ptr<Site>, int> site_of = SiteOf(state, document->id);
  const std::shared_ptr<Site>& site = site_of.first;
  const int current = site_of.second;
  if (!site) {
    throw InputError(
        fmt::format("scan {} is not a station of a site: open a file of several scans as a site, or group "
                    "open scans into "
                    "one, then fill from the other stations",
                    document->id));
  }
  const int num_stations = static_cast<int>(site->documents.size());
  std::vector<int> others;
  for (int i = 0; i < num_stations; ++i) {
    if (i != current && OpenDocumentOf(state, site->documents[i])) others.push_back(i);
  }
  const std::vector<int> chosen = IntList(body, "stations", others);
  CheckStationIndices(chosen, num_stations, "stations");
  if (std::find(chosen.begin(), chosen.end(), current) != chosen.end())
    throw OptionsFieldError("stations", fmt::format("station {} is the scan being filled", current));
  if (chosen.empty()) throw OptionsFieldError("stations", "no other open station to fill from");
  std::vector<std::shared_ptr<Document>> documents;
  for (const int i : chosen) {
    documents.push_back(OpenDocumentOf(state, site->documents[i]));
    if (!documents.back()) {
      return SendError(response, 409,
                       fmt::format("station {} (scan {}) was closed: open the site again, or leave it out "
                                   "(\"stations\")",
                                   i, site->documents[i]));
    }
  }
  {
    std::lock_guard lock(document->mutex);
    const Snapshot& now = document->now;
    const cv::Mat& mask = which == "strokes" ? now.strokes : which == "painted" ? now.hole : now.object_mask;
    if (mask.empty() || cv::countNonZero(which == "strokes" ? mask == 1 : mask) == 0) {
      throw OptionsFieldError("hole", which == "strokes"   ? "paint the object's strokes first"
                                      : which == "painted" ? "paint a hole first (hole brush or lasso)"
                                                           : "segment an object first");
    }
  }
  const int undo_depth = state.options.undo_depth;
  StartJob(
      state, document, "fill-from-stations",
      [document, documents, chosen, options, remove, which, margin, undo_depth](Progress& progress) {
        Snapshot start;
        {
          std::lock_guard lock(document->mutex);
          start = document->now;
        }
        std::vector<Scan> others;
        for (const auto& station : documents) {
          std::lock_guard lock(station->mutex);
          others.push_back(station->now.scan);
        }
        FromStationsResult filled;
        if (which == "strokes") {
          RemoveFromStationsResult result =
              RemoveObjectFromStations(start.scan, start.strokes, others, remove, options, &progress);
          filled = std::move(result.filled);
        } else {
          const cv::Mat hole =
              which == "painted" ? start.hole : GrowHole(start.object_mask, margin, start.object_box);
          filled = FillFromStations(start.scan, hole, others, options, &progress);
        }
        std::lock_guard lock(document->mutex);
        Snapshot next = document->now;
        next.scan = filled.scan;
        if (which == "strokes") {
          ClearStrokes(&next);  // a new buffer: see Snapshot
          next.object_mask = cv::Mat();
        } else {
          (which == "painted" ? next.hole : next.object_mask) = cv::Mat();
        }
        Commit(*document, std::move(next), undo_depth);
        std::vector<FillStationEntry> stations;
        for (size_t k = 0; k < chosen.size(); ++k) {
          stations.push_back({chosen[k], documents[k]->id,
                              k < filled.cells_per_station.size() ? filled.cells_per_station[k] : 0});
        }
        return ToJson(FillFromStationsReply{filled.hole_cells, filled.from_station_cells,
                                            filled.synthesized_cells, filled.no_return_cells,
                                            std::move(stations), filled.warnings, document->version});
      },
      response);
}

}  // namespace

void AddStationRoutes(State& state) {
  httplib::Server& http = state.http;
  http.Post("/api/sites", [&state](const httplib::Request& request, httplib::Response& response) {
    const auto body = BodyJson(request, response);
    if (!body) return;
    try {
      OpenSite(state, *body, response);
    } catch (const DocumentLimitError& error) {
      SendError(response, error.status, error.what());
    } catch (const OptionsError& error) {
      SendError(response, 400, error.what());
    } catch (const InputError& error) {
      SendError(response, 422, error.what());
    } catch (const nlohmann::json::exception& error) {  // a field of the wrong type
      SendError(response, 400, fmt::format("a field of the request has the wrong type: {}", error.what()));
    }
  });
  http.Get("/api/sites", [&state](const httplib::Request&, httplib::Response& response) {
    std::vector<std::shared_ptr<Site>> sites;
    {
      std::lock_guard lock(state.documents_mutex);
      for (const auto& [id, site] : state.sites) sites.push_back(site);
    }
    SitesReply reply;
    for (const auto& site : sites) reply.sites.push_back(SiteReplyOf(state, *site, -1));
    SendJson(response, ToJson(reply));
  });
  // The stations of the site a document belongs to ({"site": null, "station": -1, "stations": []} when none).
  http.Get(R"(/api/docs/(\d+)/stations)",
           [&state](const httplib::Request& request, httplib::Response& response) {
             const auto document = state.FindDocument(request, response);
             if (!document) return;
             const std::shared_ptr<Site> site = SiteOf(state, document->id).first;
             if (!site) return SendJson(response, ToJson(SiteReply{}));
             SendJson(response, ToJson(SiteReplyOf(state, *site, document->id)));
           });
  // The cells the last Clean removed from this station, as it stands now: {"version", "cells": [row * cols +
  // col, ...]} (empty once the clean is undone).
  http.Get(R"(/api/docs/(\d+)/removed)",
           [&state](const httplib::Request& request, httplib::Response& response) {
             const auto document = state.FindDocument(request, response);
             if (!document) return;
             std::vector<int64_t> cells;
             int64_t version = 0;
             {
               std::lock_guard lock(document->mutex);
               version = document->version;
               const cv::Mat& removed = document->now.removed;
               for (int r = 0; r < removed.rows; ++r) {
                 const uint8_t* row = removed.ptr<uint8_t>(r);
                 for (int c = 0; c < removed.cols; ++c) {
                   if (row[c] != 0) cells.push_back(int64_t{r} * removed.cols + c);
                 }
               }
             }
             SendJson(response, ToJson(RemovedReply{version, cells}));
           });
  PostDocument(state, R"(/api/docs/(\d+)/clean)", Clean);
  PostDocument(state, R"(/api/docs/(\d+)/fill-from-stations)", FillFromOtherStations);
}

}  // namespace lidarshop::server
