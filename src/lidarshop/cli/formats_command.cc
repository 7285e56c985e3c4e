// `lidarshop formats`: the scan formats and what each holds, from the registry (io/formats.h).
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/util/options.h"

namespace lidarshop::cli {

int RunFormats(int argc, char** argv) {
  CLI::App app{
      "List the scan formats lidarshop reads and writes and what each holds (grid and pose, several scans, "
      "channels, photos, a layer behind an object, coordinate precision): the table convert's warnings, the "
      "editor's save dialog and docs/file-formats.md come from.",
      "formats"};
  std::string json_path;
  bool markdown = false;
  AddJsonOption(app, &json_path);
  app.add_flag("--markdown", markdown, "print the table as Markdown (as in docs/file-formats.md)");
  return RunCommand(app, argc, argv, [&]() {
    if (!json_path.empty()) {
      WriteJsonOutput(json_path, ToJson(ScanFormatsSummary{SummarizeScanFormats()}));
    } else if (markdown) {
      fmt::print("{}", ScanFormatsMarkdown());
    } else {
      for (const ScanFormatInfo& format : ScanFormats()) {
        fmt::print("{:<5} {:<6} {}{}\n", format.extension, format.write ? "rw" : (format.read ? "r" : "-"),
                   format.description, format.write ? "" : fmt::format(". {}", format.write_refusal));
      }
    }
    return kExitOk;
  });
}

}  // namespace lidarshop::cli
