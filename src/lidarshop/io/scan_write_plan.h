// What writing scans to a file keeps and what it drops, by the target format (the extension): what `convert`
// says before and after it writes, so that nothing is lost silently.
//
// What each format holds comes from the registry (io/formats.h; `lidarshop formats` prints it). Beyond it:
// PTX has no way to leave the intensity column out, so a scan without intensity is written with the PTX
// no-information value 0.5, and the plan says so; XYZ and PTS write synthesized points like measured ones, and
// the plan says how many. Scan::attributes (LAS GPS time, returns, ...) are held by LAS only, the LAS
// coordinate reference system records likewise. Second returns (E57 returnIndex 1) are kept only by
// WriteE57 of a whole E57File; a caller that writes them that way passes 0 scans with second returns.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lidarshop/io/las.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct ScanWritePlan {
  // The channels written, in the target's words where it renames them: {"xyz", "intensity", "rgb",
  // "label→classification"}.
  std::vector<std::string> channels;
  // What the target cannot hold (or holds only by convention), one sentence each starting with the output
  // path, e.g. "out.ptx: labels are not written (PTX has no label field)".
  std::vector<std::string> dropped;
};

// The plan for writing `scans` to `path` (its extension decides; InputError for an unknown one), with
// `images` photos (E57 images2D) and `scans_with_second_returns` scans that have second returns in the input.
// `las` (LAS targets): the options the scans will be written with, so that attributes the chosen point
// format cannot hold are listed in `dropped` (nullptr: the defaults).
ScanWritePlan PlanScanWrite(const std::string& path, const std::vector<Scan>& scans, size_t images,
                            size_t scans_with_second_returns, const LasWriteOptions* las = nullptr);

// One line of what was written: "wrote out.las: 1 scan, 1,234,567 points, channels xyz intensity rgb
// label→classification" (plus ", 2 images" when `images_written` > 0).
std::string WrittenSummary(const std::string& path, const std::vector<Scan>& scans, size_t images_written,
                           const ScanWritePlan& plan);

// What a conversion wrote (`convert --json`): the files, the target and what it holds, as ScanWritePlan
// planned it.
struct ScanWriteSummary {
  std::string input;                            // the file read
  std::string output;                           // the file written
  std::string format;                           // the target's extension: "ptx", "e57", "las", ...
  int64_t scans = 0;                            // scans written
  int64_t returns = 0;                          // valid returns written, all scans together
  int64_t images = 0;                           // photos written (E57 images2D; 0 for every other target)
  std::vector<std::string> channels;            // ScanWritePlan::channels
  std::vector<std::string> dropped;             // ScanWritePlan::dropped, one sentence each
  std::optional<int64_t> synthesized_left_out;  // with --drop-synthesized: synthesized returns not written
};

// The summary of writing `scans` read from `input` to `output` with `images_written` photos, as `plan` said.
ScanWriteSummary SummarizeScanWrite(const std::string& input, const std::string& output,
                                    const std::vector<Scan>& scans, size_t images_written,
                                    const ScanWritePlan& plan);

template <>
const StructInfo& InfoOf<ScanWriteSummary>();

// 1234567 -> "1,234,567".
std::string WithThousandsSeparators(int64_t value);

}  // namespace lidarshop
