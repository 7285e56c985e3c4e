// The fields of a described struct that another holds, listed at the holder's own level (util/options.h): a
// result whose JSON has always been flat (`lidarshop verify --json`: VerifyResult's keys beside the report's
// own) stays one described struct without repeating the held struct's descriptions.
//
//   StructInfo info = builder.Build();
//   const std::vector<FieldInfo> flat = FlatFields(&VerifyReport::result);
//   info.fields.insert(info.fields.begin(), flat.begin(), flat.end());  // where its keys go
//
// Each field keeps its key, kind, doc, unit and range; its accessors reach into the member. The held
// struct's aliases and cross-field check are not carried over (results have none).
#pragma once

#include <vector>

#include "lidarshop/util/options.h"

namespace lidarshop {

template <class Outer, class Inner>
std::vector<FieldInfo> FlatFields(Inner Outer::*member) {
  const auto inner = [member](const void* outer) -> const void* {
    return &(static_cast<const Outer*>(outer)->*member);
  };
  const auto inner_mutable = [member](void* outer) -> void* {
    return &(static_cast<Outer*>(outer)->*member);
  };
  std::vector<FieldInfo> fields = InfoOf<Inner>().fields;
  for (FieldInfo& field : fields) {
    if (field.get) field.get = [get = field.get, inner](const void* o) { return get(inner(o)); };
    if (field.set) {
      field.set = [set = field.set, inner_mutable](void* o, const nlohmann::json& json) {
        set(inner_mutable(o), json);
      };
    }
    if (field.nested_of) {
      field.nested_of = [nested_of = field.nested_of, inner_mutable](void* o) {
        return nested_of(inner_mutable(o));
      };
    }
    if (field.list_size) {
      field.list_size = [list_size = field.list_size, inner](const void* o) { return list_size(inner(o)); };
    }
    if (field.element_of) {
      field.element_of = [element_of = field.element_of, inner_mutable](void* o, size_t index) {
        return element_of(inner_mutable(o), index);
      };
    }
    if (field.present)
      field.present = [present = field.present, inner](const void* o) { return present(inner(o)); };
  }
  return fields;
}

}  // namespace lidarshop
