// The described structs of the editor's API (docs/api.md): what its routes take under "options" and what
// its jobs answer. `lidarshop schema --typescript` writes their TypeScript declarations into
// web/src/api_types.generated.ts (the ctest api_types_test fails when that file is stale), so the front end
// uses the library's fields, not hand copies of them. A route taking or answering a described struct lists it
// here.
#pragma once

#include <string>
#include <vector>

#include "lidarshop/util/options_typescript.h"

namespace lidarshop::server {

std::vector<TypeScriptStruct> ApiTypes();

// The server's own replies and the keys its routes add beside a library result (replies.h): in the TypeScript
// file after ApiTypes(); docs/api.md documents them (docs/options.md's reference lists ApiTypes() only).
std::vector<TypeScriptStruct> ApiReplyTypes();

// The generated file's text: ApiTypes() and ApiReplyTypes() as TypeScript with its header.
std::string ApiTypesTypeScript();

}  // namespace lidarshop::server
