#include "lidarshop/io/xyz.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <limits>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/text_cursor.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using io_internal::TextCursor;

// Blank-separated tokens on the line starting at `p`.
int CountTokens(const char* p, const char* end) {
  int tokens = 0;
  bool inside = false;
  for (; p < end && *p != '\n'; ++p) {
    const bool blank = TextCursor::IsSpace(*p);
    if (!blank && !inside) ++tokens;
    inside = !blank;
  }
  return tokens;
}

struct PointList {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> intensities;  // empty without an intensity column
  std::vector<cv::Vec3b> colors;    // empty without colour columns
};

// True when the line at `p` holds a single whole number: a PTS point count (a point has 3 or more numbers).
bool IsCountLine(const char* p, const char* end) {
  if (CountTokens(p, end) != 1) return false;
  while (p < end && TextCursor::IsSpace(*p) && *p != '\n') ++p;
  if (p < end && *p == '+') ++p;
  const char* digits = p;
  while (p < end && *p >= '0' && *p <= '9') ++p;
  return p > digits && (p == end || TextCursor::IsSpace(*p));
}

PointList ParseLines(const std::string& bytes, const std::string& file, PointListKind kind,
                     std::vector<std::string>* warnings) {
  PointList list;
  TextCursor cursor(bytes, file);
  int columns = 0;
  // PTS blocks: the count a count line claims and the points that followed it. A count line that is missing
  // or wrong does not stop the reading (the points are on their lines), it is a warning.
  int64_t block_claimed = -1, block_line = 0, block_found = 0;
  bool warned_missing = false;
  auto close_block = [&]() {
    if (block_claimed >= 0 && block_found != block_claimed && warnings != nullptr) {
      warnings->push_back(
          fmt::format("{}: line {}: the point count says {} points, {} follow it; all {} were read", file,
                      block_line, block_claimed, block_found, block_found));
    }
  };
  const char* end = bytes.data() + bytes.size();
  for (;;) {
    cursor.SkipEmptyLines();
    if (cursor.AtEnd()) break;
    cursor.SkipBlanks();
    const std::string_view rest(cursor.position(), std::min<int64_t>(cursor.remaining(), 2));
    if (kind == PointListKind::kXyz && (rest.substr(0, 1) == "#" || rest == "//")) {
      cursor.NextLine();
      continue;
    }
    if (kind == PointListKind::kPts && IsCountLine(cursor.position(), end)) {
      close_block();
      block_line = cursor.line();
      block_claimed = cursor.Int("point count");
      block_found = 0;
      cursor.EndLine("the point count");
      continue;
    }
    if (kind == PointListKind::kPts && block_claimed < 0 && !warned_missing) {
      warned_missing = true;
      if (warnings != nullptr) {
        warnings->push_back(fmt::format(
            "{}: line {}: no point count line before the points (PTS starts with one); read as points", file,
            cursor.line()));
      }
    }
    if (columns == 0) {
      columns = CountTokens(cursor.position(), end);
      if (columns != 3 && columns != 4 && columns != 6 && columns != 7) {
        cursor.Fail("columns",
                    fmt::format("{} numbers on the first point line; expected x y z [intensity] [r g "
                                "b] (3, 4, 6 or 7)",
                                columns));
      }
    }
    Eigen::Vector3d p;
    p.x() = cursor.Double("x");
    p.y() = cursor.Double("y");
    p.z() = cursor.Double("z");
    for (int axis = 0; axis < 3; ++axis) {
      if (!(std::abs(p[axis]) <= kMaxCoordinateM)) {
        cursor.Fail(std::string(1, "xyz"[axis]),
                    fmt::format("{} is not a coordinate within {} m", p[axis], kMaxCoordinateM));
      }
    }
    list.points.push_back(p);
    if (columns == 4 || columns == 7) list.intensities.push_back(cursor.Double("intensity"));
    if (columns >= 6) {
      cv::Vec3b color;
      for (int c = 0; c < 3; ++c) {
        const char* name = c == 0 ? "red" : c == 1 ? "green" : "blue";
        const int64_t value = cursor.Int(name);
        if (value < 0 || value > 255) cursor.Fail(name, fmt::format("{} is not in 0-255", value));
        color[c] = static_cast<uint8_t>(value);
      }
      list.colors.push_back(color);
    }
    if (!cursor.AtEndOfLine()) {
      cursor.Fail("columns", fmt::format("more than the {} numbers of the first point line", columns));
    }
    cursor.NextLine();
    ++block_found;
  }
  close_block();
  if (list.points.empty()) ThrowInputError(file, "", "", "no points");
  return list;
}

// Intensities as [0, 1] (see xyz.h).
void NormalizeIntensities(std::vector<double>* intensities, PointListKind kind) {
  const auto [lowest, highest] = std::minmax_element(intensities->begin(), intensities->end());
  double low = std::min(0.0, *lowest), high = std::max(1.0, *highest);
  if (kind == PointListKind::kPts && *lowest >= -2048 && *highest <= 2047) low = -2048, high = 2047;
  for (double& value : *intensities) value = (value - low) / (high - low);
}

// The finest step the file prints: the most digits after a decimal point among the numbers of its first
// 64 KiB (at most 12), as metres; 0 when none has a fraction. The writers print as many, so that XYZ -> XYZ
// keeps what the file said.
double PrintedStep(const std::string& bytes) {
  int most = 0, digits = -1;
  for (size_t i = 0; i < std::min<size_t>(bytes.size(), 65536); ++i) {
    const char c = bytes[i];
    if (c == '.') {
      digits = 0;
    } else if (c >= '0' && c <= '9') {
      if (digits >= 0) most = std::max(most, ++digits);
    } else {
      digits = -1;
    }
  }
  return most == 0 ? 0.0 : std::pow(10.0, -std::min(most, 12));
}

}  // namespace

Scan ParsePointList(const std::string& bytes, const std::string& file, PointListKind kind,
                    std::vector<std::string>* warnings) {
  if (bytes.empty()) ThrowInputError(file, "line 1", "", "the file is empty");
  // Every point takes a line: the line count bounds what the lists and the scan may take.
  const int64_t lines = std::count(bytes.begin(), bytes.end(), '\n') + 1;
  io_internal::CheckScanSize(1, std::min<int64_t>(lines, kMaxScanCells + 1), file, "lines");
  PointList list = ParseLines(bytes, file, kind, warnings);
  const int count = static_cast<int>(list.points.size());
  if (!list.intensities.empty()) NormalizeIntensities(&list.intensities, kind);
  Scan scan = io_internal::UnorganizedScan(list.points, {}, !list.colors.empty(),
                                           /*with_intensity=*/!list.intensities.empty());
  for (int i = 0; i < count; ++i) {
    if (!list.intensities.empty()) scan.intensity.at<float>(0, i) = static_cast<float>(list.intensities[i]);
    if (!list.colors.empty()) scan.color.at<cv::Vec3b>(0, i) = list.colors[i];
  }
  const double step = PrintedStep(bytes);
  if (step > 0) scan.source_metadata["text.step_m"] = fmt::format("{}", step);
  return scan;
}

Scan ReadPointList(const std::string& path, PointListKind kind, std::vector<std::string>* warnings) {
  return ParsePointList(io_internal::ReadFileToString(path), path, kind, warnings);
}

void WritePointList(const std::string& path, const std::vector<Scan>& scans, PointListKind kind) {
  int64_t count = 0;
  bool color = false, intensity = false;
  for (const Scan& scan : scans) {
    CheckScan(scan);
    count += scan.CountValid();
    color |= scan.has_color();
    intensity |= scan.has_intensity();
  }
  if (count == 0) ThrowInputError(path, "", "", "no point with a return to write");
  // 5 decimals (0.01 mm), more where the source's step is finer: a LAS cloud in degrees of 1e-7, a text file
  // printed to the micrometre.
  int decimals = 5;
  for (const Scan& scan : scans) {
    for (const char* key : {"las.scale_x", "las.scale_y", "las.scale_z", "text.step_m"}) {
      const auto found = scan.source_metadata.find(key);
      if (found == scan.source_metadata.end()) continue;
      const double step = std::abs(std::strtod(found->second.c_str(), nullptr));
      if (step > 0)
        decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(step) - 1e-9)), decimals, 12);
    }
  }
  std::string out;
  out.reserve(static_cast<size_t>(count) * (color ? 56 : 44));
  auto sink = std::back_inserter(out);
  if (kind == PointListKind::kPts) fmt::format_to(sink, "{}\n", count);
  for (const Scan& scan : scans) {
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        if (!scan.valid.at<uint8_t>(row, col)) continue;
        const Eigen::Vector3d world = WorldPointOfCell(scan, row, col);
        fmt::format_to(sink, "{:.{}f} {:.{}f} {:.{}f}", world.x(), decimals, world.y(), decimals, world.z(),
                       decimals);
        if (intensity) {
          // A scan without intensity among scans with it gets the no-information value 0.5.
          const float value = scan.has_intensity() ? scan.intensity.at<float>(row, col) : 0.5f;
          out += ' ';
          if (kind == PointListKind::kPts) {
            fmt::format_to(sink, "{}", std::lround(std::clamp(value, 0.0f, 1.0f) * 4095.0f) - 2048);
          } else {
            io_internal::AppendNumber(&out, value);
          }
        }
        if (color) {
          const cv::Vec3b c = scan.has_color() ? scan.color.at<cv::Vec3b>(row, col) : cv::Vec3b(0, 0, 0);
          fmt::format_to(sink, " {} {} {}", c[0], c[1], c[2]);
        }
        out += '\n';
      }
    }
  }
  WriteFileAtomically(path, [&](std::ostream& stream) { stream.write(out.data(), out.size()); });
}

}  // namespace lidarshop
