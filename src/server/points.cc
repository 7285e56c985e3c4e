// The points of a document as typed arrays for the editor's 3-D view (docs/api.md "Points"): the whole set
// (LSP1), or only the cells that changed since a version the client holds (LSD1), so that an edit moves the
// cells it changed and not the whole scan again.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "http.h"

namespace lidarshop::server {

namespace {

constexpr uint32_t kPointsMagic = 0x3150534cu;  // "LSP1"
constexpr uint32_t kDeltaMagic = 0x3144534cu;   // "LSD1"
constexpr uint8_t kFlagSynthesized = 1, kFlagObject = 2, kFlagBehind = 4;
constexpr uint8_t kFlagFromStation = 8;       // filled from what another station of the site measured
constexpr uint32_t kBehindKey = 0x80000000u;  // a delta key's layer bit: the surface behind a kept object

// One cell's point as the client draws it.
struct PointRecord {
  bool present = false;
  float xyz[3] = {0, 0, 0};
  uint8_t rgb[3] = {0, 0, 0};
  uint8_t flags = 0;
  bool operator==(const PointRecord& other) const {
    return present == other.present && std::memcmp(xyz, other.xyz, sizeof(xyz)) == 0 &&
           std::memcmp(rgb, other.rgb, sizeof(rgb)) == 0 && flags == other.flags;
  }
};

// The point of cell (r, c) of the front scan or of the layer behind it.
PointRecord RecordAt(const Snapshot& snapshot, bool behind, int r, int c) {
  const Scan& scan = behind ? snapshot.behind : snapshot.scan;
  PointRecord record;
  if (scan.valid.empty() || r >= scan.rows || c >= scan.cols || scan.valid.at<uint8_t>(r, c) == 0)
    return record;
  record.present = true;
  const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
  std::copy(&p[0], &p[0] + 3, record.xyz);
  if (scan.has_color()) {
    const cv::Vec3b color = scan.color.at<cv::Vec3b>(r, c);
    std::copy(&color[0], &color[0] + 3, record.rgb);
  } else {
    const float intensity = scan.intensity.empty() ? 0.7f : scan.intensity.at<float>(r, c);
    const auto grey = static_cast<uint8_t>(std::clamp(intensity, 0.0f, 1.0f) * 255.0f);
    std::fill(record.rgb, record.rgb + 3, grey);
  }
  if (!scan.synthesized.empty() && scan.synthesized.at<uint8_t>(r, c) != 0) record.flags |= kFlagSynthesized;
  if (!scan.from_station.empty() && scan.from_station.at<uint8_t>(r, c) != 0)
    record.flags |= kFlagFromStation;
  if (behind) {
    record.flags |= kFlagBehind;
  } else if (!snapshot.object_mask.empty() && snapshot.object_mask.at<uint8_t>(r, c) != 0) {
    record.flags |= kFlagObject;
  }
  return record;
}

// Every buffer a layer's points are drawn from: two states whose buffers are the same (a stroke, a cut on
// another layer) have the same points there without looking at a cell.
bool SameBuffers(const Snapshot& a, const Snapshot& b, bool behind) {
  const Scan& x = behind ? a.behind : a.scan;
  const Scan& y = behind ? b.behind : b.scan;
  const auto same = [](const cv::Mat& m, const cv::Mat& n) { return m.data == n.data && m.size == n.size; };
  return same(x.valid, y.valid) && same(x.point, y.point) && same(x.color, y.color) &&
         same(x.intensity, y.intensity) && same(x.synthesized, y.synthesized) &&
         same(x.from_station, y.from_station) && (behind || same(a.object_mask, b.object_mask));
}

// Appends the typed arrays of `records` (with their keys) after `header` as the answer's bytes.
template <size_t N>
std::string Encode(const uint32_t (&header)[N], const std::vector<uint32_t>& keys,
                   const std::vector<PointRecord>& records, bool with_present) {
  const size_t n = records.size();
  std::vector<float> xyz(3 * n);
  std::vector<uint8_t> rgb(3 * n), flags(n), present(n);
  for (size_t i = 0; i < n; ++i) {
    std::copy(records[i].xyz, records[i].xyz + 3, &xyz[3 * i]);
    std::copy(records[i].rgb, records[i].rgb + 3, &rgb[3 * i]);
    flags[i] = records[i].flags;
    present[i] = records[i].present ? 1 : 0;
  }
  std::string bytes(sizeof(header), '\0');
  std::memcpy(bytes.data(), header, sizeof(header));
  const auto append = [&bytes](const auto& vector) {
    bytes.append(reinterpret_cast<const char*>(vector.data()), vector.size() * sizeof(vector[0]));
  };
  if (with_present) {  // LSD1: keys first (4-byte aligned after the 24-byte header), then the values
    append(keys);
    append(xyz);
  } else {  // LSP1: xyz, then the cells
    append(xyz);
    append(keys);
  }
  append(rgb);
  append(flags);
  if (with_present) append(present);
  return bytes;
}

// The rows or columns of the level `step` inside [first, first + count): the multiples of `step` there.
struct Lattice {
  int begin, end, step;
};
Lattice LatticeIn(int first, int count, int step) {
  return {(first + step - 1) / step * step, first + count, step};
}

// The box's rows and columns of the level (the whole grid without a box).
std::pair<Lattice, Lattice> LevelCells(const Scan& scan, int step, const std::optional<cv::Rect>& box) {
  const cv::Rect grid(0, 0, scan.cols, scan.rows);
  const cv::Rect b = box.value_or(grid) & grid;
  return {LatticeIn(b.y, b.height, step), LatticeIn(b.x, b.width, step)};
}

}  // namespace

std::optional<cv::Rect> ReadCellBox(const std::string& text, int rows, int cols) {
  int64_t v[4];
  const char* at = text.c_str();
  for (int i = 0; i < 4; ++i) {
    if (*at < '0' || *at > '9') return std::nullopt;  // no sign, no space
    char* end = nullptr;
    v[i] = std::strtoll(at, &end, 10);
    if (v[i] > INT32_MAX || *end != (i < 3 ? ',' : '\0')) return std::nullopt;
    at = end + 1;
  }
  const int64_t col = v[0], row = v[1], end_col = std::min<int64_t>(col + v[2], cols),
                end_row = std::min<int64_t>(row + v[3], rows);
  if (v[2] < 1 || v[3] < 1 || col >= end_col || row >= end_row) return std::nullopt;
  return cv::Rect(static_cast<int>(col), static_cast<int>(row), static_cast<int>(end_col - col),
                  static_cast<int>(end_row - row));
}

std::string PointsBinary(const Document& document, int step, const std::optional<cv::Rect>& box) {
  std::vector<uint32_t> cells;
  std::vector<PointRecord> records;
  for (const bool behind : {false, true}) {
    const Scan& scan = behind ? document.now.behind : document.now.scan;
    if (scan.valid.empty()) continue;
    const auto [rows, cols] = LevelCells(scan, step, box);
    for (int r = rows.begin; r < rows.end; r += step) {
      for (int c = cols.begin; c < cols.end; c += step) {
        PointRecord record = RecordAt(document.now, behind, r, c);
        if (!record.present) continue;
        records.push_back(record);
        cells.push_back(static_cast<uint32_t>(r * scan.cols + c));
      }
    }
  }
  const Scan& scan = document.now.scan;
  const uint32_t header[4] = {kPointsMagic, static_cast<uint32_t>(cells.size()),
                              static_cast<uint32_t>(scan.rows), static_cast<uint32_t>(scan.cols)};
  return Encode(header, cells, records, false);
}

void RememberState(Document& document) {
  auto& recent = document.recent;
  if (!recent.empty() && SameBuffers(recent.back().points, document.now, false) &&
      SameBuffers(recent.back().points, document.now, true)) {
    recent.back().last_version = document.version;  // the same points: a stroke, a hole
    document.counted_bytes = DocumentBytes(document);
    return;
  }
  Document::PointState state{document.version, document.version, document.now};
  state.points.strokes = cv::Mat();  // not drawn as points: not kept alive by this list
  state.points.hole = cv::Mat();
  recent.push_back(std::move(state));
  while (recent.size() > kRecentStates) recent.pop_front();
  document.counted_bytes = DocumentBytes(document);
}

std::optional<std::string> PointsDeltaBinary(const Document& document, int64_t since, int step,
                                             const std::optional<cv::Rect>& box) {
  const Snapshot* old = nullptr;
  for (const auto& state : document.recent) {
    if (state.first_version <= since && since <= state.last_version) old = &state.points;
  }
  const Snapshot& now = document.now;
  const int rows = now.scan.rows, cols = now.scan.cols;
  if (old == nullptr || old->scan.rows != rows || old->scan.cols != cols ||
      int64_t{rows} * cols >= int64_t{kBehindKey} || since > UINT32_MAX || document.version > UINT32_MAX) {
    return std::nullopt;
  }
  std::vector<uint32_t> keys;
  std::vector<PointRecord> records;
  const auto [level_rows, level_cols] = LevelCells(now.scan, step, box);
  for (const bool behind : {false, true}) {
    if (SameBuffers(*old, now, behind)) continue;
    for (int r = level_rows.begin; r < level_rows.end; r += step) {
      for (int c = level_cols.begin; c < level_cols.end; c += step) {
        PointRecord record = RecordAt(now, behind, r, c);
        if (record == RecordAt(*old, behind, r, c)) continue;
        keys.push_back(static_cast<uint32_t>(r * cols + c) | (behind ? kBehindKey : 0));
        records.push_back(record);
      }
    }
  }
  const uint32_t header[6] = {kDeltaMagic,
                              static_cast<uint32_t>(records.size()),
                              static_cast<uint32_t>(rows),
                              static_cast<uint32_t>(cols),
                              static_cast<uint32_t>(since),
                              static_cast<uint32_t>(document.version)};
  return Encode(header, keys, records, true);
}

}  // namespace lidarshop::server
