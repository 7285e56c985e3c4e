// Routes that open, describe, show and save scans (docs/api.md).
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "http.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/render/render.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/text.h"
#include "replies.h"
#include "version_param.h"

namespace lidarshop::server {

namespace fs = std::filesystem;

void SendError(httplib::Response& response, int status, const std::string& message) {
  response.status = status;
  // Cut (a message may quote the request) and with bytes that are not UTF-8 replaced (a path or header
  // quoted as sent), so that writing the answer cannot throw.
  response.set_content(ToJson(ErrorReply{Excerpt(message, kMaxErrorBytes)})
                           .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                       "application/json");
}

void SendJson(httplib::Response& response, const nlohmann::ordered_json& json, int status) {
  response.status = status;
  response.set_content(json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                       "application/json");
}

namespace {

// How deep `text` nests arrays and objects (brackets inside strings do not count); stops counting past `limit`.
int JsonDepth(const std::string& text, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size() && deepest <= limit; ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

}  // namespace

std::optional<nlohmann::json> BodyJson(const httplib::Request& request, httplib::Response& response) {
  if (request.is_multipart_form_data()) {  // a form's body, which httplib has taken apart (request.files)
    SendError(response, 415,
              "the request body must be JSON sent as Content-Type: application/json, not a form");
    return std::nullopt;
  }
  if (request.body.empty()) return nlohmann::json::object();
  // Only a body a page could not send without asking first (a cross-origin fetch with this type needs a CORS
  // preflight, which this server never grants; a form or a text/plain fetch cannot set it).
  std::string type = request.get_header_value("Content-Type");
  type = type.substr(0, type.find(';'));
  type.erase(type.find_last_not_of(" \t") + 1);
  type = AsciiLower(type);
  if (type != "application/json") {
    SendError(response, 415,
              fmt::format("the request body must be JSON sent as Content-Type: application/json (was '{}')",
                          Excerpt(request.get_header_value("Content-Type"), 100)));
    return std::nullopt;
  }
  // A JSON body is parsed into about 10 times its size, and each level of nesting costs an allocation: both
  // are bounded before parsing (a 60 MB body of '[' took 1.9 GB). Photos, the one large upload, are not JSON.
  if (request.body.size() > kMaxJsonBodyBytes) {
    SendError(response, 413,
              fmt::format("the JSON body of {} bytes exceeds the limit of {} bytes for JSON requests",
                          request.body.size(), kMaxJsonBodyBytes));
    return std::nullopt;
  }
  if (JsonDepth(request.body, kMaxJsonDepth) > kMaxJsonDepth) {
    SendError(response, 400, fmt::format("the request body nests JSON deeper than {} levels", kMaxJsonDepth));
    return std::nullopt;
  }
  try {
    nlohmann::json json = nlohmann::json::parse(request.body);
    if (!json.is_object()) {
      SendError(response, 400, "the request body must be a JSON object");
      return std::nullopt;
    }
    return json;
  } catch (const nlohmann::json::exception& error) {  // a syntax error, or a number past double's range
    SendError(response, 400, fmt::format("the request body is not JSON: {}", error.what()));
    return std::nullopt;
  }
}

std::string ResolveUnderRoots(const std::vector<std::string>& roots, const std::string& requested) {
  if (requested.empty() || requested.find('\0') != std::string::npos) return "";
  for (const auto& part : fs::path(requested)) {
    if (part == "..") return "";
  }
  std::vector<fs::path> candidates;
  if (fs::path(requested).is_absolute()) {
    candidates.push_back(requested);
  } else {
    for (const std::string& root : roots) candidates.push_back(fs::path(root) / requested);
  }
  for (const fs::path& candidate : candidates) {
    std::error_code error;
    const fs::path real = fs::canonical(candidate, error);  // follows every symlink
    if (error) continue;
    for (const std::string& root : roots) {
      const std::string root_slash = root.back() == '/' ? root : root + "/";
      if (real.string().rfind(root_slash, 0) == 0) return real.string();
    }
  }
  return "";
}

void SendPng(httplib::Response& response, const cv::Mat& rgb_or_gray) {
  // A new buffer for the BGR copy: `rgb_or_gray` may be a kept picture (pictures.cc), not to be swapped in place.
  cv::Mat out;
  if (rgb_or_gray.channels() == 3) {
    cv::cvtColor(rgb_or_gray, out, cv::COLOR_RGB2BGR);
  } else {
    out = rgb_or_gray;
  }
  std::vector<uint8_t> png;
  CvImEncode(".png", out, &png);
  response.set_content(std::string(png.begin(), png.end()), "image/png");
}

namespace {

// Adds `mat`'s buffer to `seen`, keyed by its allocation: shallow copies (the snapshots') count once.
void AddBuffer(const cv::Mat& mat, std::map<const void*, int64_t>& seen) {
  if (mat.empty()) return;
  const void* key = mat.u != nullptr ? static_cast<const void*>(mat.u) : mat.datastart;
  seen[key] = static_cast<int64_t>(mat.total() * mat.elemSize());
}

void CollectBuffers(const Scan& scan, std::map<const void*, int64_t>& seen) {
  for (const cv::Mat* mat :
       {&scan.direction, &scan.valid, &scan.range, &scan.point, &scan.intensity, &scan.color, &scan.label,
        &scan.normal, &scan.curvature, &scan.true_range, &scan.synthesized, &scan.from_station}) {
    AddBuffer(*mat, seen);
  }
  for (const auto& [name, mat] : scan.attributes) AddBuffer(mat, seen);
}

void CollectBuffers(const Snapshot& snapshot, std::map<const void*, int64_t>& seen) {
  CollectBuffers(snapshot.scan, seen);
  CollectBuffers(snapshot.behind, seen);
  for (const cv::Mat* mat : {&snapshot.strokes, &snapshot.object_mask, &snapshot.hole, &snapshot.removed})
    AddBuffer(*mat, seen);
}

int64_t Sum(const std::map<const void*, int64_t>& seen) {
  int64_t bytes = 0;
  for (const auto& [buffer, size] : seen) bytes += size;
  return bytes;
}

}  // namespace

int64_t DocumentBytes(const Document& document) { return DocumentBytesWith(document, Snapshot{}); }

int64_t DocumentBytesWith(const Document& document, const Snapshot& next) {
  std::map<const void*, int64_t> seen;
  CollectBuffers(next, seen);
  CollectBuffers(document.now, seen);
  for (const auto* history : {&document.undo, &document.redo}) {
    for (const Snapshot& snapshot : *history) CollectBuffers(snapshot, seen);
  }
  for (const auto& state : document.recent) CollectBuffers(state.points, seen);
  AddBuffer(document.photo, seen);
  AddBuffer(document.photo_b, seen);
  for (const E57Image& image : document.e57_images) {
    AddBuffer(image.image, seen);
    seen[image.encoded.data()] = static_cast<int64_t>(image.encoded.size());
  }
  return Sum(seen);
}

void State::CheckRoomForDocument(int64_t more_bytes) {
  std::vector<std::shared_ptr<Document>> open;
  {
    std::lock_guard lock(documents_mutex);
    for (const auto& [id, document] : documents) open.push_back(document);
  }
  if (static_cast<int>(open.size()) >= options.max_documents) {
    throw DocumentLimitError(409, fmt::format("{} scans are open, the most this server keeps: close one (its "
                                              "unsaved edits are yours to save first), then open this one",
                                              open.size()));
  }
  if (more_bytes <= 0) return;
  const int64_t limit = options.max_document_bytes > 0 ? options.max_document_bytes : MemoryBudgetBytes();
  int64_t used = 0;
  for (const auto& document : open) {
    std::lock_guard lock(document->mutex);
    used += DocumentBytes(*document);
  }
  if (used + more_bytes > limit) {
    throw DocumentLimitError(
        507, fmt::format("not enough memory for this scan: it needs {} MiB and the {} open scans (with their "
                         "undo history) hold {} MiB of the {} MiB allowed; close one, then open this one",
                         more_bytes >> 20, open.size(), used >> 20, limit >> 20));
  }
}

void State::CheckRoomForEdit(const Document& document, int64_t bytes_after) {
  const int64_t limit = options.max_document_bytes > 0 ? options.max_document_bytes : MemoryBudgetBytes();
  int64_t others = 0;
  {
    std::lock_guard lock(documents_mutex);
    for (const auto& [id, open] : documents) {
      if (open.get() != &document) others += open->counted_bytes.load();
    }
  }
  if (others + bytes_after > limit) {
    throw DocumentLimitError(
        507,
        fmt::format("not enough memory for this edit: the scan would hold {} MiB (with its undo history) "
                    "and the other open scans hold {} MiB of the {} MiB allowed; the scan is kept as it "
                    "was: save and close another scan, then try again",
                    bytes_after >> 20, others >> 20, limit >> 20));
  }
}

FileForEditing ReadFileForEditing(const std::string& path) {
  if (FileExtension(path) != "e57") return {ReadScanFile(path), {}};
  E57File e57 = ReadE57(path);  // as ReadScanFile reads it, keeping the photos
  FileForEditing opened;
  opened.file.path = path;
  opened.file.format = "e57";
  opened.file.scans = std::move(e57.scans);
  opened.file.warnings = std::move(e57.warnings);
  opened.images = std::move(e57.images);
  return opened;
}

std::vector<E57Image> ImagesOfScan(const std::vector<E57Image>& images, int index) {
  std::vector<E57Image> kept;
  for (const E57Image& image : images) {
    if (image.associated_scan != index && image.associated_scan != -1) continue;
    kept.push_back(image);
    kept.back().associated_scan = image.associated_scan == index ? 0 : -1;
  }
  return kept;
}

int State::AddDocument(std::string name, Scan scan, std::vector<E57Image> e57_images) {
  auto document = std::make_shared<Document>();
  document->name = std::move(name);
  document->e57_images = std::move(e57_images);
  document->now.scan = std::move(scan);
  ClearStrokes(&document->now);
  std::lock_guard open_lock(open_mutex);
  CheckRoomForDocument(DocumentBytes(*document));
  document->check_room = [this](const Document& self, int64_t bytes_after) {
    CheckRoomForEdit(self, bytes_after);
  };
  RememberState(*document);
  std::lock_guard lock(documents_mutex);
  document->id = ++last_document;
  documents[document->id] = document;
  return document->id;
}

std::shared_ptr<Document> State::Get(int id) {
  std::lock_guard lock(documents_mutex);
  return documents.at(id);
}

std::shared_ptr<ModelEntry> State::FindModel(int id) {
  std::lock_guard lock(documents_mutex);
  const auto found = models.find(id);
  return found == models.end() ? nullptr : found->second;
}

std::shared_ptr<Document> State::FindDocument(const httplib::Request& request, httplib::Response& response) {
  const int id = std::atoi(request.matches[1].str().c_str());
  std::lock_guard lock(documents_mutex);
  const auto found = documents.find(id);
  if (found == documents.end()) {
    SendError(response, 404, fmt::format("no open scan {}", id));
    return nullptr;
  }
  return found->second;
}

StrokeCounts CountStrokes(const cv::Mat& strokes) {
  StrokeCounts counts;
  for (int y = 0; y < strokes.rows; ++y) {
    const uint8_t* row = strokes.ptr<uint8_t>(y);
    int64_t object = 0, background = 0;
    for (int x = 0; x < strokes.cols; ++x) {
      object += row[x] == 1;
      background += row[x] == 2;
    }
    counts.object += object;
    counts.background += background;
  }
  return counts;
}

namespace {

// The photos a document carries from its E57 file ("usable": decoded, so the recolour tool can take it).
std::vector<E57ImageEntry> E57ImageEntries(const std::vector<E57Image>& images) {
  std::vector<E57ImageEntry> list;
  for (size_t i = 0; i < images.size(); ++i) {
    list.push_back({i, images[i].name, images[i].image.empty() ? images[i].width_px : images[i].image.cols,
                    images[i].image.empty() ? images[i].height_px : images[i].image.rows,
                    !images[i].image.empty()});
  }
  return list;
}

DocumentReply DocumentOf(Document& document) {
  std::lock_guard lock(document.mutex);
  const Scan& scan = document.now.scan;
  std::vector<std::string> channels;
  for (const auto& [name, image] : {std::pair{"range", &scan.range},
                                    {"point", &scan.point},
                                    {"intensity", &scan.intensity},
                                    {"color", &scan.color},
                                    {"label", &scan.label},
                                    {"normal", &scan.normal},
                                    {"synthesized", &scan.synthesized}}) {
    if (!image->empty()) channels.push_back(name);
  }
  std::vector<double> pose(scan.world_from_scanner.data(), scan.world_from_scanner.data() + 16);
  // Angular steps of the grid, for square angular pixels on screen (0 when the scan has no grid).
  const auto step_deg = [](const std::vector<double>& angles) {
    return angles.size() < 2 ? 0.0
                             : std::abs(angles.back() - angles.front()) / (angles.size() - 1) * 180.0 / M_PI;
  };
  return {document.id,
          document.name,
          scan.rows,
          scan.cols,
          channels,
          scan.CountValid(),
          scan.synthesized.empty() ? 0 : cv::countNonZero(scan.synthesized),
          document.now.object_mask.empty() ? 0 : document.now.object_cells,
          document.now.hole.empty() ? 0 : cv::countNonZero(document.now.hole),
          document.now.object_stroke_cells,
          document.now.background_stroke_cells,
          document.now.behind.valid.empty() ? 0 : cv::countNonZero(document.now.behind.valid),
          pose,
          step_deg(scan.grid.azimuth_rad),
          step_deg(scan.grid.elevation_rad),
          document.version,
          !document.undo.empty(),
          !document.redo.empty(),
          E57ImageEntries(document.e57_images)};
}

nlohmann::ordered_json DocumentJson(Document& document) { return ToJson(DocumentOf(document)); }

void Open(State& state, const httplib::Request& request, httplib::Response& response) {
  if (request.has_param("scene")) {
    const std::string name = request.get_param_value("scene");
    const auto& names = state.options.builtin_scenes;
    if (std::find(names.begin(), names.end(), name) == names.end() || !state.options.scan_builtin) {
      SendError(response, 404, fmt::format("no built-in scene '{}'", name));
      return;
    }
    try {
      state.CheckRoomForDocument();  // before scanning it
      const int id = state.AddDocument(name, state.options.scan_builtin(name));
      SendJson(response, DocumentJson(*state.Get(id)));
    } catch (const DocumentLimitError& error) {
      SendError(response, error.status, error.what());
    }
    return;
  }
  const std::string requested = request.get_param_value("path");
  const std::string path = ResolveUnderRoots(state.options.roots, requested);
  if (path.empty()) {
    SendError(response, 403,
              fmt::format("'{}' is not a file under the folders this server was started with", requested));
    return;
  }
  try {
    state.CheckRoomForDocument();  // before reading the file
    FileForEditing opened = ReadFileForEditing(path);
    ScanFile& file = opened.file;
    const int index = request.has_param("scan") ? std::atoi(request.get_param_value("scan").c_str()) : 0;
    if (index < 0 || index >= static_cast<int>(file.scans.size())) {
      SendError(response, 400,
                fmt::format("scan {} is out of range: the file holds {}", index, file.scans.size()));
      return;
    }
    const int id = state.AddDocument(fs::path(path).filename().string(), std::move(file.scans[index]),
                                     ImagesOfScan(opened.images, index));
    // With what the reader left out of the file.
    SendJson(response, Joined(DocumentJson(*state.Get(id)), ToJson(WarningsReply{file.warnings})));
  } catch (const DocumentLimitError& error) {
    SendError(response, error.status, error.what());
  } catch (const InputError& error) {
    SendError(response, 422, error.what());
  }
}

// The written format the request asks for (`format`, E57 by default), or nullptr after a 400 naming the
// formats the library writes.
const ScanFormatInfo* RequestedWriteFormat(const httplib::Request& request, httplib::Response& response) {
  const std::string format = request.has_param("format") ? request.get_param_value("format") : "e57";
  const ScanFormatInfo* info = FindScanFormat(format);
  if (info == nullptr || !info->write) {
    SendError(response, 400,
              fmt::format("format '{}': expected one of {}", format.substr(0, 32),
                          fmt::join(SupportedScanWriteExtensions(), ", ")));
    return nullptr;
  }
  return info;
}

void Save(Document& document, const httplib::Request& request, httplib::Response& response) {
  const ScanFormatInfo* info = RequestedWriteFormat(request, response);
  if (info == nullptr) return;
  const std::string format(info->extension);
  // The writers take a path: the file goes through a folder of its own that only this user can enter
  // (mkdtemp: a new, unpredictable name, mode 0700), so no other user can pre-create it, follow a symlink
  // into it, or read the scan while it is written.
  std::string pattern = (fs::temp_directory_path() / "lidarshop-save-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    SendError(response, 507,
              fmt::format("cannot make a temporary folder to save in: {}", std::strerror(errno)));
    return;
  }
  const fs::path folder = pattern;
  struct RemoveFolder {
    fs::path path;
    ~RemoveFolder() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } remove_folder{folder};
  const fs::path file = folder / fmt::format("doc{}.{}", document.id, format);
  {
    std::lock_guard lock(document.mutex);
    if (format == "e57" && !document.e57_images.empty()) {
      // The photos of the file it was opened from go back with it (with the scan's guid and dates, which
      // the scan keeps in its source_metadata).
      E57File e57;
      e57.scans = {document.now.scan};
      e57.images = document.e57_images;
      if (!document.now.behind.valid.empty()) e57.second_returns = {document.now.behind};
      WriteE57(file.string(), e57, E57WriteOptions{});
    } else if (document.now.behind.valid.empty()) {
      WriteScanFile(file.string(), {document.now.scan});
    } else if (!info->layer_behind) {
      SendError(response, 400, LayerBehindRefusal(*info));
      return;
    } else {
      WriteScanWithLayer(file.string(), document.now.scan, document.now.behind);
    }
  }
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string stem = fs::path(document.name).stem().string();
  response.set_header("Content-Disposition", fmt::format("attachment; filename=\"{}.{}\"", stem, format));
  response.set_content(std::move(bytes), "application/octet-stream");
}

// What saving in `format` keeps and drops (io/scan_write_plan.h, the registry's answer), asked before the
// save so that the editor can warn: {"format", "channels", "dropped", "refused"}; "refused" is the reason a
// save in that format would fail ("" when it would not).
void SavePlan(Document& document, const httplib::Request& request, httplib::Response& response) {
  const ScanFormatInfo* info = RequestedWriteFormat(request, response);
  if (info == nullptr) return;
  const std::string format(info->extension);
  std::lock_guard lock(document.mutex);
  const bool layer = !document.now.behind.valid.empty();
  const ScanWritePlan plan = PlanScanWrite(
      fmt::format("{}.{}", fs::path(document.name).stem().string(), format), {document.now.scan}, 0, 0);
  std::vector<std::string> dropped = plan.dropped;
  if (format != "e57" && !document.e57_images.empty()) {
    dropped.push_back(
        fmt::format("{}: the {} photo(s) of the E57 file (images2D) are not written; E57 keeps them", format,
                    document.e57_images.size()));
  }
  SendJson(response, ToJson(SavePlanReply{format, plan.channels, dropped,
                                          layer && !info->layer_behind ? LayerBehindRefusal(*info) : ""}));
}

}  // namespace

void AddScanRoutes(State& state) {
  httplib::Server& http = state.http;
  http.Get("/api/health", [](const httplib::Request&, httplib::Response& response) {
    SendJson(response, ToJson(HealthReply{}));
  });
  // The scan formats the library reads and writes (the open and save dialogs offer these).
  http.Get("/api/formats", [](const httplib::Request&, httplib::Response& response) {
    SendJson(response, ToJson(FormatsReply{SupportedScanReadExtensions(), SupportedScanWriteExtensions(),
                                           SummarizeScanFormats()}));
  });
  http.Get("/api/scenes", [&state](const httplib::Request&, httplib::Response& response) {
    SendJson(response, ToJson(ScenesReply{state.options.builtin_scenes}));
  });
  // The file dialog: scan files under the roots (at most 2000, two folders deep).
  http.Get("/api/files", [&state](const httplib::Request&, httplib::Response& response) {
    std::vector<FileEntry> files;
    const std::vector<std::string> readable = SupportedScanReadExtensions();
    for (const std::string& root : state.options.roots) {
      std::error_code error;
      for (auto it = fs::recursive_directory_iterator(root, error);
           !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
        if (it.depth() > 1) it.disable_recursion_pending();
        if (!it->is_regular_file()) continue;
        // A temporary of an atomic write (a writer killed mid-way left it) is no file to open.
        if (IsAtomicTemporary(it->path().filename().string())) continue;
        const std::string extension = FileExtension(it->path().string());
        if (std::find(readable.begin(), readable.end(), extension) == readable.end()) continue;
        files.push_back({it->path().string(), it->file_size(), false, std::nullopt});
        if (files.size() >= 2000) break;
      }
    }
    // In name order, each with whether its header reads (io/scan_header.h: the header only, cheap), so that the
    // dialog offers the first file that opens rather than a broken one the folder happened to list first. A
    // file whose real path leaves the roots (a symlink) is not read: opening it is refused anyway.
    std::sort(files.begin(), files.end(),
              [](const FileEntry& a, const FileEntry& b) { return a.path < b.path; });
    for (FileEntry& file : files) {
      if (ResolveUnderRoots(state.options.roots, file.path).empty()) {
        file.error = "outside the served folders";
        continue;
      }
      try {
        ReadScanHeader(file.path);
        file.readable = true;
      } catch (const std::exception& error) {
        file.error = error.what();
      }
    }
    SendJson(response, ToJson(FilesReply{state.options.roots, std::move(files)}));
  });
  http.Get("/api/open", [&state](const httplib::Request& request, httplib::Response& response) {
    Open(state, request, response);
  });
  http.Get("/api/docs", [&state](const httplib::Request&, httplib::Response& response) {
    std::vector<std::shared_ptr<Document>> documents;
    {
      std::lock_guard lock(state.documents_mutex);
      for (const auto& [id, document] : state.documents) documents.push_back(document);
    }
    DocumentsReply reply;
    for (const auto& document : documents) reply.documents.push_back(DocumentOf(*document));
    SendJson(response, ToJson(reply));
  });
  http.Get(R"(/api/docs/(\d+))", [&state](const httplib::Request& request, httplib::Response& response) {
    if (auto document = state.FindDocument(request, response)) SendJson(response, DocumentJson(*document));
  });
  http.Delete(R"(/api/docs/(\d+))", [&state](const httplib::Request& request, httplib::Response& response) {
    if (auto document = state.FindDocument(request, response)) {
      std::lock_guard lock(state.documents_mutex);
      state.documents.erase(document->id);
      SendJson(response, ToJson(ClosedReply{document->id}));
    }
  });
  http.Get(R"(/api/docs/(\d+)/image.png)", [&state](const httplib::Request& request,
                                                    httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    RenderOptions options;
    try {
      const std::string channel = request.has_param("channel") ? request.get_param_value("channel") : "range";
      options.channel = ParseEnum<RenderChannel>(channel);
      // ?since=V: only the box of pixels that changed since version V (pictures.cc).
      int64_t since = -1;
      if (!ReadSinceParam(request, response, &since)) return;
      std::lock_guard lock(document->mutex);
      SendRayPicture(*document, options, channel, since, response);
    } catch (const OptionsError& error) {
      SendError(response, 400, error.what());
    } catch (const InputError& error) {
      SendError(response, 422, error.what());  // e.g. rgb of a scan without colour
    }
  });
  http.Get(R"(/api/docs/(\d+)/mask.png)", [&state](const httplib::Request& request,
                                                   httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    std::lock_guard lock(document->mutex);
    const Scan& scan = document->now.scan;
    const std::string layer = request.get_param_value("layer");
    // crop=1: only the box of the drawn cells (headers X-Lidarshop-Box, X-Lidarshop-Size).
    const bool crop = request.get_param_value("crop") == "1";
    if (layer == "strokes") {
      // The strokes as the server holds them (the canvas draws these, not a list of its own): the
      // object's green, the background's red, half transparent; the rest clear (BGRA overlay), or
      // the values 0 / 1 / 2 as grey (segment.h kStroke*).
      const cv::Mat& strokes = document->now.strokes;
      if (request.get_param_value("style") != "overlay") return SendPng(response, strokes);
      // Cropped: only the box of the painted cells is drawn (a large scan's overlay is mostly clear).
      // (Every stroke lies in strokes_box: only that is read.)
      const cv::Rect box = crop ? NonZeroBoxWithin(strokes, document->now.strokes_box)
                                : cv::Rect(0, 0, strokes.cols, strokes.rows);
      if (box.empty()) return SendOverlay(response, cv::Mat(), &box, strokes.size());
      const cv::Mat part = strokes(box);
      cv::Mat overlay(part.size(), CV_8UC4, cv::Scalar(0, 0, 0, 0));
      overlay.setTo(cv::Scalar(60, 220, 60, 210), part == 1);
      overlay.setTo(cv::Scalar(60, 60, 230, 210), part == 2);
      return SendOverlay(response, overlay, crop ? &box : nullptr, strokes.size());
    }
    const bool hole = layer == "hole";
    const cv::Mat& chosen = hole ? document->now.hole : document->now.object_mask;
    cv::Mat mask = chosen.empty() ? cv::Mat::zeros(scan.rows, scan.cols, CV_8U) : chosen;
    if (request.get_param_value("style") != "overlay") return SendPng(response, mask);
    // For drawing over the ray image: the object orange, the hole blue, half transparent; the rest clear (BGRA).
    // (The object's cells lie in its box: only that is read, a station's mask is 100 MB.)
    const cv::Rect whole(0, 0, mask.cols, mask.rows);
    const cv::Rect box =
        crop ? NonZeroBoxWithin(mask, !hole && !chosen.empty() ? document->now.object_box : whole) : whole;
    if (box.empty()) return SendOverlay(response, cv::Mat(), &box, mask.size());
    cv::Mat overlay(box.size(), CV_8UC4, cv::Scalar(0, 0, 0, 0));
    overlay.setTo(hole ? cv::Scalar(255, 120, 40, 150) : cv::Scalar(0, 140, 255, 150), mask(box));
    SendOverlay(response, overlay, crop ? &box : nullptr, mask.size());
  });
  http.Get(R"(/api/docs/(\d+)/points)", [&state](const httplib::Request& request,
                                                 httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    // ?since=V: only the cells that changed since the client's version V (LSD1), when that state is
    // still kept; else (or without it) the whole points (LSP1). The client tells them by the magic.
    int64_t since = -1;
    if (!ReadSinceParam(request, response, &since)) return;
    // ?step=K: the level of detail K (every K-th row and column), for a large scan's first view.
    int64_t step = 1;
    if (!ReadWholeNumberParam(request, response, "step", 1, 64, "a whole number in [1, 64]", &step)) return;
    std::lock_guard lock(document->mutex);
    // ?box=COL,ROW,WIDTH,HEIGHT: only the cells inside it (clipped to the grid; header X-Lidarshop-Box).
    std::optional<cv::Rect> box;
    if (request.has_param("box")) {
      box = ReadCellBox(request.get_param_value("box"), document->now.scan.rows, document->now.scan.cols);
      if (!box) {
        return SendError(response, 400,
                         fmt::format("box: expected COL,ROW,WIDTH,HEIGHT (whole numbers, width and "
                                     "height >= 1) overlapping the scan's {} x {} cells",
                                     document->now.scan.cols, document->now.scan.rows));
      }
      SetBoxHeader(response, *box);
    }
    response.set_header("X-Lidarshop-Version", std::to_string(document->version));
    response.set_header("X-Lidarshop-Step", std::to_string(step));
    if (since >= 0) {
      if (auto delta = PointsDeltaBinary(*document, since, static_cast<int>(step), box)) {
        return response.set_content(std::move(*delta), "application/octet-stream");
      }
    }
    response.set_content(PointsBinary(*document, static_cast<int>(step), box), "application/octet-stream");
  });
  // The object labels of a synthetic scan: cells, bounding box and centre per label (the object list).
  http.Get(R"(/api/docs/(\d+)/labels)",
           [&state](const httplib::Request& request, httplib::Response& response) {
             auto document = state.FindDocument(request, response);
             if (!document) return;
             std::lock_guard lock(document->mutex);
             const Scan& scan = document->now.scan;
             std::map<int32_t, std::array<int64_t, 7>>
                 stats;  // cells, min row, min col, max row, max col, sum r, sum c
             if (!scan.label.empty()) {
               for (int r = 0; r < scan.rows; ++r) {
                 for (int c = 0; c < scan.cols; ++c) {
                   if (scan.valid.at<uint8_t>(r, c) == 0) continue;
                   auto [it, added] = stats.try_emplace(scan.label.at<int32_t>(r, c),
                                                        std::array<int64_t, 7>{0, r, c, r, c, 0, 0});
                   auto& s = it->second;
                   s = {s[0] + 1,
                        std::min<int64_t>(s[1], r),
                        std::min<int64_t>(s[2], c),
                        std::max<int64_t>(s[3], r),
                        std::max<int64_t>(s[4], c),
                        s[5] + r,
                        s[6] + c};
                 }
               }
             }
             LabelsReply reply;
             for (const auto& [label, s] : stats)
               reply.labels.push_back({label, s[0], {s[1], s[2], s[3], s[4]}, {s[5] / s[0], s[6] / s[0]}});
             SendJson(response, ToJson(reply));
           });
  http.Get(R"(/api/docs/(\d+)/save)", [&state](const httplib::Request& request, httplib::Response& response) {
    if (auto document = state.FindDocument(request, response)) Save(*document, request, response);
  });
  http.Get(R"(/api/docs/(\d+)/save-plan)",
           [&state](const httplib::Request& request, httplib::Response& response) {
             if (auto document = state.FindDocument(request, response))
               SavePlan(*document, request, response);
           });
}

}  // namespace lidarshop::server
