// Descriptions of the file options (util/options.h); the picture options are render/'s.
#include <fmt/format.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const StructInfo& InfoOf<PtxReadOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PtxReadOptions> b("PtxReadOptions", "reading PTX");
    b.Field(&PtxReadOptions::fit_grid, "fit_grid", "fit the angular grid so every cell gets a direction");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57WriteOptions>() {
  static const StructInfo info = [] {
    StructBuilder<E57WriteOptions> b("E57WriteOptions", "writing E57");
    b.Field(&E57WriteOptions::coordinate_scale_m, "coordinate_scale_m",
            "0 = float coordinates; > 0 = scaled integers with this step")
        .Unit("m")
        .Min(0);
    b.Field(&E57WriteOptions::write_no_return_directions, "write_no_return_directions",
            "keep the directions of cells without a return (in lidarshop's E57 extension; never as points)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LasWriteOptions>() {
  static const StructInfo info = [] {
    StructBuilder<LasWriteOptions> b("LasWriteOptions", "writing LAS");
    b.Field(&LasWriteOptions::minor_version, "minor_version",
            "LAS 1.x: 4 (LAS 1.4) or 2 (LAS 1.2, formats 0-3)")
        .Range(2, 4);
    b.Field(&LasWriteOptions::point_format, "point_format",
            "point data record format 0-3 or 6-8; -1 = the source LAS's when it holds the attributes, else "
            "8 with NIR, 7 with colour, 6 (1.4); 3/2 with colour, 1/0 (1.2; GPS time decides)")
        .Range(-1, 8);
    b.Field(&LasWriteOptions::coordinate_scale_m, "coordinate_scale_m", "step of the stored coordinates")
        .Unit("m")
        .AboveZero()
        .Max(1);
    b.Field(&LasWriteOptions::keep_source_scale, "keep_source_scale",
            "keep the source LAS files' scale and offset when all scans share them (same integers back)");
    b.Check([](const LasWriteOptions& o) {
      CheckOption(
          o.minor_version == 2 || o.minor_version == 4,
          fmt::format("minor_version: {} is not written; 4 (LAS 1.4) or 2 (LAS 1.2)", o.minor_version));
      CheckOption(o.point_format != 4 && o.point_format != 5,
                  fmt::format("point_format: {} (waveform) is not written; 0-3 or 6-8", o.point_format));
      CheckOption(o.point_format < 6 || o.minor_version == 4,
                  fmt::format("point_format: {} needs LAS 1.4 (minor_version 4)", o.point_format));
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanWriteSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanWriteSummary> b("ScanWriteSummary", "what a conversion wrote (convert --json)");
    b.Field(&ScanWriteSummary::input, "input", "the file read");
    b.Field(&ScanWriteSummary::output, "output", "the file written");
    b.Field(&ScanWriteSummary::format, "format", "the target format: its extension (ptx, e57, las, ...)");
    b.Field(&ScanWriteSummary::scans, "scans", "scans written");
    b.Field(&ScanWriteSummary::returns, "returns", "valid returns written, all scans together")
        .Unit("points");
    b.Field(&ScanWriteSummary::images, "images", "photos written (E57 images2D; 0 for other targets)");
    b.Field(&ScanWriteSummary::channels, "channels",
            "the channels written, in the target's words where it renames them (label→classification)");
    b.Field(&ScanWriteSummary::dropped, "dropped",
            "what the target cannot hold, one sentence each starting with the output path");
    b.Field(&ScanWriteSummary::synthesized_left_out, "synthesized_left_out",
            "with --drop-synthesized: the synthesized returns left out")
        .Unit("points");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
