// The reference part of docs/options.md, from the described structs (util/options.h): one section per struct
// with a table of its fields (key, type, default, unit, range, doc), so the page cannot disagree with the CLI's
// help, the JSON or the Python classes. `lidarshop schema --markdown -o docs/options.md` writes it below the
// page's hand-written part; the ctest options_md_test fails when the committed page is not what it writes.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "lidarshop/util/options_typescript.h"

namespace lidarshop {

// The line that ends the hand-written part of a generated page; everything after it is generated.
inline constexpr std::string_view kGeneratedMarker =
    "<!-- Generated below by `lidarshop schema --markdown -o docs/options.md` from the descriptions: do not "
    "edit. -->";

// One section per struct of `structs` and per struct nested in them, each once (by StructInfo::name; two
// different descriptions of one name throw OptionsError), in the order they first appear. An options
// struct's defaults are its own (S{}); a nested field whose holder starts it elsewhere (FillOptions::inpaint)
// names the values that differ. Aliases (older keys of nested fields) are listed under their struct.
std::string MarkdownReference(const std::vector<TypeScriptStruct>& structs);

// `page` up to and including kGeneratedMarker, then `reference`. Throws OptionsError when `page` has no
// marker (the hand-written part would be lost).
std::string ReplaceGeneratedPart(const std::string& page, const std::string& reference);

}  // namespace lidarshop
