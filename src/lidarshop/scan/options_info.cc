// Descriptions of the scan module's options (util/options.h).
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const StructInfo& InfoOf<ScanMeshOptions>() {
  static const StructInfo info = [] {
    StructBuilder<ScanMeshOptions> b("ScanMeshOptions", "the triangle mesh of a scan's grid");
    b.Field(&ScanMeshOptions::max_range_jump_ratio, "max_range_jump_ratio",
            "largest relative range difference of a kept edge")
        .AboveZero();
    b.Field(&ScanMeshOptions::max_edge_m, "max_edge_m", "longest kept edge; 0 = no limit").Unit("m").Min(0);
    b.Field(&ScanMeshOptions::world_frame, "world_frame", "vertices in the world frame, not the scanner's");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
