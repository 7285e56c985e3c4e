// `lidarshop schema`: the described structs of the editor's API (server/api_types.h) as TypeScript
// declarations (web/src/api_types.generated.ts; the ctest api_types_test keeps that file current) or as
// JSON descriptions (each field's key, kind, doc, unit, range, choices and nested struct).
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "api_types.h"
#include "lidarshop/cli/commands.h"
#include "lidarshop/util/atomic_file.h"

namespace lidarshop::cli {

int RunSchema(int argc, char** argv) {
  CLI::App app{
      "The option and result structs of the editor's API as the library describes them (src/server/"
      "api_types.cc): TypeScript declarations for the front end (--typescript) or their descriptions as "
      "JSON (--json).",
      "schema"};
  std::string json_path, output;
  bool typescript = false;
  AddJsonOption(app, &json_path);
  app.add_flag("--typescript", typescript,
               "write the TypeScript declarations (web/src/api_types.generated.ts)");
  app.add_option("-o,--output", output, "with --typescript: the file to write (default: stdout)");
  return RunCommand(app, argc, argv, [&]() {
    if (typescript && !json_path.empty()) throw OptionsError("--typescript and --json: give one");
    if (!output.empty() && !typescript) throw OptionsError("--output goes with --typescript");
    if (typescript) {
      if (!output.empty()) CheckOutputFile("--output", output, {"ts"}, {});
      const std::string text = server::ApiTypesTypeScript();
      if (output.empty()) {
        fmt::print("{}", text);
      } else {
        WriteFileAtomically(output, [&](std::ostream& stream) { stream << text; });
        Summarize(fmt::format("{} structs -> {}", server::ApiTypes().size(), output));
      }
    } else if (!json_path.empty()) {
      nlohmann::ordered_json list = nlohmann::ordered_json::array();
      for (const TypeScriptStruct& entry : server::ApiTypes()) {
        nlohmann::ordered_json description = DescriptionJson(*entry.info);
        description["result"] = entry.answer;
        list.push_back(std::move(description));
      }
      WriteJsonOutput(json_path, {{"structs", list}});
    } else {
      throw OptionsError("give --typescript or --json FILE");
    }
    return kExitOk;
  });
}

}  // namespace lidarshop::cli
