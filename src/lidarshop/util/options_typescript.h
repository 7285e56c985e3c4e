// TypeScript declarations of described structs (util/options.h): the types of the editor's API
// (web/src/api_types.generated.ts, written by `lidarshop schema --typescript`), so that a field described once
// in a module's options_info.cc is a field of the front end's types too, with its doc, unit, range and
// default as a comment. The text is what Prettier writes for it (web/.prettierrc.json: 110 columns, single
// quotes), so `npm run lint` passes on the generated file as it is.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/util/options.h"

namespace lidarshop {

struct TypeScriptStruct {
  const StructInfo* info = nullptr;
  // The struct's default JSON form (ToJson(S{})) shown in the comments; null for results.
  nlohmann::ordered_json defaults;
  // A result: its numbers may be null (a NaN, "none", is JSON null; util/options.h), so they are typed
  // `number | null`. Options never hold NaN (their ranges reject it).
  bool answer = false;
};

// Visits `structs` in order, then the structs nested in them as first met (breadth first), each name once:
// `visit(entry, push)` handles one and calls `push` for each struct it holds. Throws OptionsError when two
// different structs share a name.
void VisitDescribedStructs(
    const std::vector<TypeScriptStruct>& structs,
    const std::function<void(const TypeScriptStruct&, const std::function<void(TypeScriptStruct)>&)>& visit);

template <class S>
TypeScriptStruct OptionsType() {
  return {&InfoOf<S>(), ToJson(S{}), false};
}
template <class S>
TypeScriptStruct ResultType() {
  return {&InfoOf<S>(), nullptr, true};
}

// One `export interface` per struct of `structs` and per struct nested in them (each once, named by
// StructInfo::name; two different descriptions of one name throw OptionsError), one commented member per
// field: booleans, numbers, strings, number and string lists, enums as unions of their names, nested structs by
// name. `header` (comment lines, each starting with "//") opens the file.
std::string TypeScriptDeclarations(const std::vector<TypeScriptStruct>& structs, std::string_view header);

// The description of `info` and its nested structs as JSON (for tools and tests): {"name", "doc", "fields": [{"key",
// "kind", "doc", "unit", "range", "choices", "optional" (true for a std::optional member), "struct"}]}, and
// "aliases": [{"key", "alias_of", "range"}] when it has some.
nlohmann::ordered_json DescriptionJson(const StructInfo& info);

// `lidarshop schema --json`: {"structs": [the DescriptionJson of each of `structs`, in order, with "result": true
// for a result and false for options]}.
nlohmann::ordered_json SchemaJson(const std::vector<TypeScriptStruct>& structs);

}  // namespace lidarshop
