// Reading and writing scan files, chosen by file extension (a table, Open3D style; what each format holds is
// the registry of io/formats.h).
//
//   .ptx  Leica ASCII, one or many organized scans            read + write
//   .e57  ASTM E2807, organized and unstructured scans, images read + write (io/e57.h)
//   .ply  points with colour/normal/label/synthesized fields   read + write (a scan becomes its valid points;
//         the grid is kept in element properties `row`/`col` when written by lidarshop; another PLY is one
//         1 x N cloud, io_common.h UnorganizedScan)
//   .pcd  PCL, organized clouds (ascii, binary, binary_compressed) read + write (io/pcd.h: the numbers are the
//         world points, VIEWPOINT the sensor pose)
//   .las  ASPRS LAS 1.0-1.4, point formats 0-10 read; 1.4/1.2 formats 0-3, 6-8 written (io/las.h): one
//         unorganized cloud in the world frame (several scans are written as one cloud, point source ID =
//         scan index)
//   .laz  LAS compressed by LASzip, read as .las (io/laz.h: point formats 0-3, 6-8); not written ("LAZ is
//         not written: ... write .las instead")
//   .xyz  ASCII "x y z [intensity] [r g b]", world frame, one cloud           read + write (io/xyz.h)
//   .pts  Leica PTS: a point count line, then as .xyz                        read + write
//
// Unorganized formats (PLY clouds, unorganized PCD, LAS, XYZ, PTS) keep every point, (0, 0, 0) included, as float
// offsets from an origin held in the pose; organized ones (PTX, E57, organized PCD) mark a missing return so.
// Readers reject malformed input with an InputError naming the file, the line or byte offset and the field;
// they refuse before allocating when a header claims more cells than memory allows. Writers are atomic.
#pragma once

#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

struct ScanFile {
  std::string path;
  std::string format;       // "ptx", "e57", "ply", "pcd", "las", "laz", "xyz", "pts"
  std::vector<Scan> scans;  // several registered scans where the format allows it
  // What the reader left out or changed while reading a file it could still read, one sentence each,
  // starting with the file's path (e.g. E57 returns beyond the second). The library does not print them;
  // the CLI prints them on stderr, the server returns them with the opened document.
  std::vector<std::string> warnings;
};

// Reads every scan in `path`. Throws InputError (unknown extension, malformed content); what it can read
// but not keep comes back in ScanFile::warnings.
ScanFile ReadScanFile(const std::string& path);

// Writes `scans` in the format of `path`'s extension. A format that holds one scan only (PCD) throws
// InputError when given several. Scans of 0 cells (an E57 data3D entry of 0 records) are written to E57 only:
// the other formats leave them out, and throw InputError ("no point to write") when no scan is left, rather
// than write a file that no reader (ours included) takes as a scan. Atomic.
void WriteScanFile(const std::string& path, const std::vector<Scan>& scans);

// Writes `front` with a second layer `behind` it (`remove --keep-object`: the kept object in front, the
// filled background behind). Both share the grid (rows x cols, directions) and pose; `behind` holds returns
// only in some cells and is synthesized by definition.
//   .e57  one data3D: `front` as WriteE57 writes it, plus each valid `behind` cell as a second return of the
//         same rowIndex/columnIndex (returnIndex 1, returnCount 2; lidarshop:synthesized = 1); ReadE57 gives
//         the layers back as scans[0] and second_returns[0] (io/e57.h, WriteE57WithLayer)
//   .ply  two scans of one grid (scan 0 = front, scan 1 = behind, synthesized = 1), world frame: a plain
//         PLY reader sees the union of both layers' points with the `synthesized` field
//   .pcd  one unorganized cloud (HEIGHT 1, world frame) of both layers' valid points, `synthesized` 0 for
//         measured points of `front` (or its own flags) and 1 for `behind`
//   .las  one cloud of both layers' valid points (world frame), the layer behind with the synthetic flag
//   .ptx .xyz .pts  InputError: LayerBehindRefusal (io/formats.h), "PTX cannot hold two returns per cell; write
//         E57, PLY, PCD or LAS"
// Throws InputError naming `path` when the layers differ in size or pose. Atomic.
void WriteScanWithLayer(const std::string& path, const Scan& front, const Scan& behind);

// Throws InputError (the same as WriteScanFile would) when `path` has no written scan format's extension
// (unknown, or .laz); lets a command refuse an output path before its work.
void CheckScanFileFormat(const std::string& path);
// The same for an input path (as ReadScanFile would): unknown extensions.
void CheckScanFileReadable(const std::string& path);

// The extensions (lower case, no dot) of the scan formats ReadScanFile reads and WriteScanFile writes, in the
// table's order: what a file dialog offers. A format added to the table appears here by itself.
std::vector<std::string> SupportedScanReadExtensions();
std::vector<std::string> SupportedScanWriteExtensions();

// The lower-case extension without the dot ("ptx"), or "" when none.
std::string FileExtension(const std::string& path);

// The largest number of cells a header may claim before a reader refuses it (about 4 GiB of channels).
constexpr int64_t kMaxScanCells = int64_t{1} << 28;

}  // namespace lidarshop
