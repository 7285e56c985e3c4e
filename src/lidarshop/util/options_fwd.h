// Declarations for headers that describe their options structs and enums (util/options.h,
// util/enum_names.h) without pulling in JSON.
#pragma once

#include "lidarshop/util/enum_names.h"

namespace lidarshop {

struct StructInfo;

// The description of options struct S; each module specializes it for its structs in options_info.cc.
template <class S>
const StructInfo& InfoOf();

}  // namespace lidarshop
