// Descriptions of the ray-casting options and enums (util/options.h).
#include "lidarshop/raycast/raycast.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<CastMethod>() {
  static const EnumInfo info = MakeEnumInfo<CastMethod>(
      "cast method", {{CastMethod::kPacket16, "packet16", "4 x 4 tiles as rtcIntersect16 packets"},
                      {CastMethod::kPacket8, "packet8", "2 x 4 tiles as rtcIntersect8 packets"},
                      {CastMethod::kStream, "stream", "rows of tiles as coherent rtcIntersect1M streams"},
                      {CastMethod::kSingle, "single", "one rtcIntersect1 per ray (the reference)"}});
  return info;
}

template <>
const StructInfo& InfoOf<RaycastSceneOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RaycastSceneOptions> b("RaycastSceneOptions", "the Embree scene");
    b.Field(&RaycastSceneOptions::build_quality, "build_quality",
            "Embree BVH build quality: low, medium or high");
    b.Field(&RaycastSceneOptions::robust, "robust", "rays through a shared edge do not slip through");
    b.Field(&RaycastSceneOptions::compact, "compact", "less memory, slower traversal");
    b.Check([](const RaycastSceneOptions& o) {
      if (o.build_quality != "low" && o.build_quality != "medium" && o.build_quality != "high") {
        throw OptionsFieldError("build_quality",
                                fmt::format("'{}' is not low, medium or high", o.build_quality));
      }
    });
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
