// The colour maps' names (util/enum_names.h).
#include "lidarshop/image/colormap.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<ColorMap>() {
  static const EnumInfo info = MakeEnumInfo<ColorMap>(
      "colour map", {{ColorMap::kViridis, "viridis", "perceptual, dark blue to yellow"},
                     {ColorMap::kTurbo, "turbo", "rainbow-like, perceptually smoother"},
                     {ColorMap::kMagma, "magma", "perceptual, black to light yellow"},
                     {ColorMap::kGray, "gray", "black to white"}});
  return info;
}

}  // namespace lidarshop
