#include "lidarshop/io/ptx.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/SVD>

#include "lidarshop/geometry/transform.h"

#include "lidarshop/io/io_common.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/text_cursor.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

using io_internal::TextCursor;

// Reads "a b c" (or "a b c d") of a header line into `values`.
template <int N>
void ReadHeaderLine(TextCursor* cursor, const char* what, double* values) {
  cursor->SkipEmptyLines();
  if (cursor->AtEnd()) cursor->Fail(what, "the file ends inside the scan header");
  static const char* kNames[] = {"1st value", "2nd value", "3rd value", "4th value"};
  for (int i = 0; i < N; ++i) values[i] = cursor->Double(fmt::format("{} ({})", what, kNames[i]));
  cursor->EndLine(what);
}

int64_t ReadCount(TextCursor* cursor, const char* what, int scan_index) {
  cursor->SkipEmptyLines();
  if (cursor->AtEnd()) cursor->Fail(what, "the file ends inside the scan header");
  const std::string_view token = cursor->Token();
  TextCursor number(token, cursor->file(), cursor->line());
  int64_t count = 0;
  try {
    count = number.Int(what);
  } catch (const InputError&) {
    std::string hint;
    if (scan_index > 0) {
      hint = fmt::format(
          " (expected the header of scan {}; does scan {} have more point lines than its header "
          "claims?)",
          scan_index + 1, scan_index);
    }
    cursor->Fail(what,
                 fmt::format("expected a whole number, found '{}'{}", io_internal::Printable(token), hint));
  }
  if (!cursor->AtEndOfLine()) {
    cursor->Fail(what,
                 fmt::format("expected one whole number on the line{}",
                             scan_index > 0 ? fmt::format(" (header of scan {}; does scan {} have more point "
                                                          "lines than its header claims?)",
                                                          scan_index + 1, scan_index)
                                            : std::string()));
  }
  cursor->NextLine();
  return count;
}

// A scan's 10 header lines: its size and pose.
struct PtxScanHead {
  int64_t rows = 0, cols = 0;
  // The rigid pose: the file's transform, or its rotation and position when the transform carries a scale.
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  // What takes the file's scanner-frame points into the pose's scanner frame: identity for a rigid transform,
  // else R^T · A (A the transform's 3 x 3, R its rotation), which applies the scale to the points.
  bool apply_linear = false;  // scanner_from_file is not the identity
  bool scaled = false;        // ... and more than the rounding of a printed rotation: a warning
  Eigen::Matrix3d scanner_from_file = Eigen::Matrix3d::Identity();
  double scale = 1.0;  // det(A)^(1/3)
};

PtxScanHead ParseScanHead(TextCursor* cursor, int scan_index) {
  const std::string place = fmt::format("scan {}", scan_index + 1);
  const int64_t header_line = cursor->line();
  const int64_t cols = ReadCount(cursor, "columns", scan_index);
  const int64_t rows = ReadCount(cursor, "rows", scan_index);
  io_internal::CheckScanSize(rows, cols, cursor->file(), fmt::format("line {}: {}", header_line, place));
  double position[3], axes[3][3], printed[4][4];
  ReadHeaderLine<3>(cursor, "scanner position", position);
  ReadHeaderLine<3>(cursor, "scanner x axis", axes[0]);
  ReadHeaderLine<3>(cursor, "scanner y axis", axes[1]);
  ReadHeaderLine<3>(cursor, "scanner z axis", axes[2]);
  for (int i = 0; i < 4; ++i) {
    static const char* kRows[] = {"matrix row 1", "matrix row 2", "matrix row 3", "matrix row 4"};
    ReadHeaderLine<4>(cursor, kRows[i], printed[i]);
  }
  // Every point line takes at least 7 characters ("0 0 0 0") and a line end: refuse a header that claims more
  // lines than the rest of the file can hold before allocating the scan.
  const int64_t remaining = cursor->remaining();
  if (rows * cols * 8 - 1 > remaining) {
    ThrowInputError(
        cursor->file(), fmt::format("line {}: {}", header_line, place), "size",
        fmt::format("truncated: {} rows x {} columns need at least {} bytes of point lines, {} follow", rows,
                    cols, rows * cols * 8 - 1, remaining));
  }
  Eigen::Matrix4d matrix;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) matrix(r, c) = printed[r][c];
  }
  // Leica prints the transpose (translation in the 4th printed row). A matrix printed the usual way has "0 0
  // 0 1" as its last row and a translation in the last column: take it as printed.
  const bool usual_layout = printed[3][0] == 0 && printed[3][1] == 0 && printed[3][2] == 0 &&
                            (printed[0][3] != 0 || printed[1][3] != 0 || printed[2][3] != 0);
  PtxScanHead head;
  head.rows = rows;
  head.cols = cols;
  head.world_from_scanner = usual_layout ? matrix : Eigen::Matrix4d(matrix.transpose());
  const Eigen::RowVector4d last_row = head.world_from_scanner.row(3);
  if (!last_row.isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-9)) {
    ThrowInputError(cursor->file(), fmt::format("line {}: {}", cursor->line() - 1, place), "matrix",
                    "not an affine transform: the printed 4th column (Leica layout) must be 0 0 0 1");
  }
  // A rotation printed to a few decimals is not quite orthonormal (E57 and other writers refuse such a pose):
  // the pose takes its nearest rotation R (polar decomposition A = R · S, by SVD) and the points S · p, so the
  // world coordinates stay the transform's. A transform that scales the scanner's axes (PDAL applies the whole
  // matrix to the points; each scale within [1e-3, 1e3]) is read the same way, with a warning. Anything else
  // (shear, mirror, a singular or absurd matrix) stays as printed and is refused by CheckScanNumbers.
  const Eigen::Matrix3d linear = head.world_from_scanner.topLeftCorner<3, 3>();
  if (IsRigid(head.world_from_scanner, 1e-12)) return head;
  const bool rigid = PoseProblem(head.world_from_scanner, /*allow_uniform_scale=*/false).empty();
  if (!rigid) {
    if (!linear.allFinite() || !(linear.determinant() > 0)) return head;
    const Eigen::Vector3d scales = linear.colwise().norm().transpose();
    if (!(scales.minCoeff() >= 1e-3 && scales.maxCoeff() <= 1e3)) return head;
    const Eigen::Matrix3d normalized = linear * scales.cwiseInverse().asDiagonal();
    if (!(normalized.transpose() * normalized).isApprox(Eigen::Matrix3d::Identity(), 1e-4)) return head;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  head.apply_linear = true;
  head.scaled = !rigid;
  head.scale = std::cbrt(linear.determinant());
  head.scanner_from_file = rotation.transpose() * linear;
  head.world_from_scanner.topLeftCorner<3, 3>() = rotation;
  return head;
}

// Points beyond kScanRangeKeptM of the scanner (georeferenced points with an identity transform, as PDAL
// writes them) are kept relative to a local origin near them, held in the pose (io_common.h); `direction`
// holds each point's remainder (ParseOneScan).
void MoveToLocalOrigin(Scan* scan, const Eigen::Vector3d& near_origin, const std::string& place,
                       const std::string& file, std::vector<std::string>* warnings) {
  std::vector<Eigen::Vector3d> points(static_cast<size_t>(scan->num_cells()));
  std::vector<uint8_t> valid(points.size(), 0);
  for (int row = 0; row < scan->rows; ++row) {
    for (int col = 0; col < scan->cols; ++col) {
      const size_t cell = static_cast<size_t>(row) * scan->cols + col;
      if (!scan->valid.ptr<uint8_t>(row)[col]) continue;
      const cv::Vec3f& p = scan->point.ptr<cv::Vec3f>(row)[col];
      const cv::Vec3f& rest = scan->direction.ptr<cv::Vec3f>(row)[col];
      points[cell] = Eigen::Vector3d(double{p[0]} + rest[0], double{p[1]} + rest[1], double{p[2]} + rest[2]);
      valid[cell] = 1;
    }
  }
  const Eigen::Vector3d origin = io_internal::OriginClearOfPoints(near_origin, points, valid);
  for (int row = 0; row < scan->rows; ++row) {
    for (int col = 0; col < scan->cols; ++col) {
      const size_t cell = static_cast<size_t>(row) * scan->cols + col;
      if (!valid[cell]) continue;
      const Eigen::Vector3f p = (points[cell] - origin).cast<float>();
      scan->point.ptr<cv::Vec3f>(row)[col] = cv::Vec3f(p.x(), p.y(), p.z());
    }
  }
  scan->world_from_scanner.topRightCorner<3, 1>() += scan->world_from_scanner.topLeftCorner<3, 3>() * origin;
  if (warnings != nullptr) {
    warnings->push_back(fmt::format(
        "{}: {}: the points lie more than {} m from the scanner origin: they are not read as its rays but "
        "relative to a local origin near them, so that floats keep the file's precision; the scanner "
        "position "
        "is not kept and the directions are from that origin",
        file, place, io_internal::kScanRangeKeptM));
  }
}

Scan ParseOneScan(TextCursor* cursor, int scan_index, const PtxReadOptions& options,
                  std::vector<std::string>* warnings) {
  const std::string place = fmt::format("scan {}", scan_index + 1);
  const PtxScanHead head = ParseScanHead(cursor, scan_index);
  const int64_t rows = head.rows, cols = head.cols;
  Scan scan = MakeScan(static_cast<int>(rows), static_cast<int>(cols));
  scan.world_from_scanner = head.world_from_scanner;
  // Points are parsed as doubles and kept as floats; `direction` holds, until FinishScan sets the directions,
  // what the float left of the double (a float too), so that a scan whose points lie far from its origin can
  // be moved to a local origin afterwards without losing the file's precision.
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), high = -low;

  const int64_t total = rows * cols;
  int64_t done = 0;
  for (int64_t col = 0; col < cols; ++col) {
    for (int64_t r = 0; r < rows; ++r, ++done) {
      cursor->SkipEmptyLines();
      if (cursor->AtEnd()) {
        cursor->Fail("", fmt::format("truncated: {} expects {} point lines ({} columns x {} rows), found {}",
                                     place, total, cols, rows, done));
      }
      const int image_row = static_cast<int>(rows - 1 - r);
      Eigen::Vector3d point;
      point.x() = cursor->Double("x");
      point.y() = cursor->Double("y");
      point.z() = cursor->Double("z");
      const float intensity = cursor->Float("intensity");
      const bool valid = !point.isZero();
      if (!cursor->AtEndOfLine()) {
        const int64_t red = cursor->Int("red");
        const int64_t green = cursor->Int("green");
        const int64_t blue = cursor->Int("blue");
        if ((red | green | blue) < 0 || red > 255 || green > 255 || blue > 255) {
          cursor->Fail("colour", fmt::format("{} {} {} is outside 0-255", red, green, blue));
        }
        if (!cursor->AtEndOfLine()) {
          cursor->Fail("", "expected 4 fields (x y z intensity) or 7 fields (x y z intensity r g b)");
        }
        if (scan.color.empty()) scan.color = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));
        if (valid) {
          scan.color.ptr<cv::Vec3b>(image_row)[col] =
              cv::Vec3b(static_cast<uint8_t>(red), static_cast<uint8_t>(green), static_cast<uint8_t>(blue));
        }
      }
      cursor->NextLine();
      if (valid) {
        if (head.apply_linear) point = head.scanner_from_file * point;
        low = low.cwiseMin(point);
        high = high.cwiseMax(point);
        const Eigen::Vector3f rounded = point.cast<float>();
        if (!rounded.allFinite()) {
          ThrowInputError(cursor->file(), fmt::format("line {}", cursor->line() - 1), "x y z",
                          fmt::format("number out of range: {} {} {}", point.x(), point.y(), point.z()));
        }
        const Eigen::Vector3f rest = (point - rounded.cast<double>()).cast<float>();
        scan.valid.ptr<uint8_t>(image_row)[col] = kValid;
        scan.point.ptr<cv::Vec3f>(image_row)[col] = cv::Vec3f(rounded.x(), rounded.y(), rounded.z());
        scan.direction.ptr<cv::Vec3f>(image_row)[col] = cv::Vec3f(rest.x(), rest.y(), rest.z());
        scan.intensity.ptr<float>(image_row)[col] = intensity;
      }
    }
  }
  if (head.scaled && warnings != nullptr) {
    warnings->push_back(
        fmt::format("{}: {}: the transform carries a scale (det^(1/3) = {:.6g}): applied to the points, as "
                    "PDAL does; the "
                    "scanner pose keeps the transform's rotation and position",
                    cursor->file(), place, head.scale));
  }
  // Coordinates past kMaxCoordinateM are left for CheckScanNumbers to refuse by cell.
  if ((low.array() <= high.array()).all() && low.cwiseAbs().maxCoeff() <= kMaxCoordinateM &&
      high.cwiseAbs().maxCoeff() <= kMaxCoordinateM) {
    const Eigen::Vector3d far_origin = io_internal::FarScanOrigin(low, high);
    if (!far_origin.isZero()) MoveToLocalOrigin(&scan, far_origin, place, cursor->file(), warnings);
  }
  io_internal::FinishScan(&scan, options.fit_grid);
  return scan;
}

}  // namespace

std::vector<Scan> ParsePtx(std::string_view text, const std::string& file, const PtxReadOptions& options,
                           std::vector<std::string>* warnings) {
  TextCursor cursor(text, file);
  std::vector<Scan> scans;
  cursor.SkipEmptyLines();
  if (cursor.AtEnd()) ThrowInputError(file, "line 1", "columns", "the file is empty");
  // Every scan costs its cells and a fixed part (its channels' headers, its grid) that a 60-byte scan of one
  // point would make dominant: at most one scan per kBytesPerScan bytes of file (7 MB of 100,000 one-point
  // scans took 793 MB), and every scan read so far within the budget.
  constexpr int64_t kBytesPerScan = 4096, kScanFixedBytes = 16384;
  const int64_t max_scans = std::max<int64_t>(64, static_cast<int64_t>(text.size()) / kBytesPerScan);
  int64_t bytes_so_far = 0;
  while (!cursor.AtEnd()) {
    if (static_cast<int64_t>(scans.size()) >= max_scans) {
      ThrowInputError(file, fmt::format("line {}", cursor.line()), "columns",
                      fmt::format("more than {} scans in {} bytes (at most one per {} bytes)", max_scans,
                                  text.size(), kBytesPerScan));
    }
    scans.push_back(ParseOneScan(&cursor, static_cast<int>(scans.size()), options, warnings));
    bytes_so_far += kScanFixedBytes + scans.back().num_cells() * io_internal::kScanBytesPerCell;
    CheckMemoryBudget(bytes_so_far, fmt::format("{}: {} scans", file, scans.size()));
    cursor.SkipEmptyLines();
  }
  return scans;
}

std::vector<ScanHeader> io_internal::ReadPtxHeaders(const std::string& path) {
  const int64_t size = CheckRegularFile(path);
  if (size == 0) ThrowInputError(path, "line 1", "columns", "the file is empty");
  // Mapped, not read: the point lines are only skipped, so a large file costs page cache, not memory.
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) ThrowInputError(path, "", "", "cannot open for reading");
  void* mapped = ::mmap(nullptr, static_cast<size_t>(size), PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (mapped == MAP_FAILED) ThrowInputError(path, "", "", "cannot map the file for reading");
  struct Unmap {
    void* data;
    size_t size;
    ~Unmap() { ::munmap(data, size); }
  } unmap{mapped, static_cast<size_t>(size)};
  ::madvise(mapped, static_cast<size_t>(size), MADV_SEQUENTIAL);
  // Pages already skipped leave the process (they stay in the page cache): the memory stays flat.
  const uintptr_t page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
  uintptr_t dropped = reinterpret_cast<uintptr_t>(mapped);
  auto drop_behind = [&](const char* position) {
    const uintptr_t until = reinterpret_cast<uintptr_t>(position) / page * page;
    if (until > dropped) {
      ::madvise(reinterpret_cast<void*>(dropped), until - dropped, MADV_DONTNEED);
      dropped = until;
    }
  };
  TextCursor cursor(std::string_view(static_cast<const char*>(mapped), static_cast<size_t>(size)), path);
  std::vector<ScanHeader> scans;
  cursor.SkipEmptyLines();
  if (cursor.AtEnd()) ThrowInputError(path, "line 1", "columns", "the file is empty");
  while (!cursor.AtEnd()) {
    const int scan_index = static_cast<int>(scans.size());
    const PtxScanHead head = ParseScanHead(&cursor, scan_index);
    ScanHeader scan;
    scan.organized = true;
    scan.rows = head.rows;
    scan.cols = head.cols;
    scan.points = head.rows * head.cols;
    scan.world_from_scanner = head.world_from_scanner;
    scan.channels = {"xyz", "range", "intensity", "valid", "direction"};
    // The first point line says whether the scan has colour (7 fields) or not (4).
    cursor.SkipEmptyLines();
    int fields = 0;
    for (TextCursor line = cursor; !line.AtEndOfLine(); ++fields) line.Token();
    if (fields == 7) scan.channels.push_back("rgb");
    const int64_t total = head.rows * head.cols;
    for (int64_t done = 0; done < total; ++done) {
      if ((done & 0xFFFFF) == 0) drop_behind(cursor.position());
      cursor.SkipEmptyLines();
      if (cursor.AtEnd()) {
        cursor.Fail("",
                    fmt::format("truncated: scan {} expects {} point lines ({} columns x {} rows), found {}",
                                scan_index + 1, total, head.cols, head.rows, done));
      }
      cursor.NextLine();
    }
    scans.push_back(std::move(scan));
    cursor.SkipEmptyLines();
  }
  return scans;
}

std::vector<Scan> ReadPtx(const std::string& path, const PtxReadOptions& options,
                          std::vector<std::string>* warnings) {
  const std::string text = io_internal::ReadFileToString(path);
  return ParsePtx(text, path, options, warnings);
}

std::string FormatPtx(const std::vector<Scan>& scans) {
  using io_internal::AppendNumber;
  std::string out;
  int64_t cells = 0;
  for (const Scan& scan : scans) cells += scan.num_cells();
  out.reserve(static_cast<size_t>(cells) * 40 + 1024);
  for (const Scan& scan : scans) {
    CheckScan(scan);
    const Eigen::Matrix4d& pose = scan.world_from_scanner;
    out += fmt::format("{}\n{}\n", scan.cols, scan.rows);
    auto append_row = [&](std::initializer_list<double> values) {
      bool first = true;
      for (double value : values) {
        if (!first) out += ' ';
        AppendNumber(&out, value);
        first = false;
      }
      out += '\n';
    };
    append_row({pose(0, 3), pose(1, 3), pose(2, 3)});
    for (int axis = 0; axis < 3; ++axis) append_row({pose(0, axis), pose(1, axis), pose(2, axis)});
    // Leica layout: the transpose of world_from_scanner.
    for (int c = 0; c < 4; ++c) append_row({pose(0, c), pose(1, c), pose(2, c), pose(3, c)});
    const bool color = scan.has_color();
    for (int col = 0; col < scan.cols; ++col) {
      for (int row = scan.rows - 1; row >= 0; --row) {
        if (!scan.valid.ptr<uint8_t>(row)[col]) {
          out += color ? "0 0 0 0.5 0 0 0\n" : "0 0 0 0.5\n";
          continue;
        }
        const cv::Vec3f& point = scan.point.ptr<cv::Vec3f>(row)[col];
        AppendNumber(&out, point[0]);
        out += ' ';
        AppendNumber(&out, point[1]);
        out += ' ';
        AppendNumber(&out, point[2]);
        out += ' ';
        // PTX has no way to leave the intensity column out: a scan without intensity gets the format's
        // no-information value 0.5 (convert warns that the PTX holds it; ReadPtx reads it back as intensity).
        AppendNumber(&out, scan.has_intensity() ? scan.intensity.ptr<float>(row)[col] : 0.5f);
        if (color) {
          const cv::Vec3b& rgb = scan.color.ptr<cv::Vec3b>(row)[col];
          for (int channel = 0; channel < 3; ++channel) {
            out += ' ';
            AppendNumber(&out, static_cast<int64_t>(rgb[channel]));
          }
        }
        out += '\n';
      }
    }
  }
  return out;
}

void WritePtx(const std::string& path, const std::vector<Scan>& scans) {
  const std::string text = FormatPtx(scans);
  WriteFileAtomically(path, [&](std::ostream& stream) { stream.write(text.data(), text.size()); });
}

}  // namespace lidarshop
