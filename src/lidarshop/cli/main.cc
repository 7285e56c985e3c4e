// lidarshop — edit terrestrial LiDAR scans. `lidarshop <command> --help` for each command.
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "lidarshop/cli/command_line.h"
#include "lidarshop/cli/commands.h"
#include "lidarshop/util/memory_budget.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      {"demo", lidarshop::cli::RunDemo, "run the main job on a built-in scene, results in ./out/"},
      {"scan", lidarshop::cli::RunScan, "synthesize a scan of a scene description (JSON)"},
      {"info", lidarshop::cli::RunInfo, "describe a scan file as JSON"},
      {"convert", lidarshop::cli::RunConvert, "convert between PTX, E57, PLY, PCD, LAS, XYZ and PTS"},
      {"formats", lidarshop::cli::RunFormats, "the scan formats and what each holds"},
      {"render", lidarshop::cli::RunRender, "render a channel of a scan as a picture"},
      {"verify", lidarshop::cli::RunVerify, "consistency and confidence of an object pose"},
      {"sweep", lidarshop::cli::RunSweep, "verification heat maps over candidate poses"},
      {"segment", lidarshop::cli::RunSegment, "cut an object out of a scan from two strokes"},
      {"inpaint", lidarshop::cli::RunInpaint, "patch-based image inpainting"},
      {"poisson", lidarshop::cli::RunPoisson, "Poisson image editing: fill, clone, reconstruct"},
      {"fill", lidarshop::cli::RunFill, "fill a hole in a scan (gradient-domain inpainting + Poisson)"},
      {"remove", lidarshop::cli::RunRemove, "remove an object from a scan: cut it out and fill behind it"},
      {"resection", lidarshop::cli::RunResection, "the camera of a photo from pixel <-> point pairs"},
      {"recolor", lidarshop::cli::RunRecolor, "recolour a scan from a photo (occlusion-aware)"},
      {"images", lidarshop::cli::RunImages, "list or extract the photos of an E57 file"},
      {"align", lidarshop::cli::RunAlign, "landmark transform, homography or fundamental matrix"},
      {"photo", lidarshop::cli::RunPhoto, "render a synthetic photo of a scene"},
      {"points", lidarshop::cli::RunPoints,
       "point-set tools: outliers, voxel, crop, normals, planes, clusters"},
      {"register", lidarshop::cli::RunRegister, "register one scan onto another (point-to-plane ICP)"},
      {"clean", lidarshop::cli::RunClean, "remove what moved between the stations of a site"},
      {"serve", lidarshop::cli::RunServe, "the editor in the browser: look, paint, segment, remove, save"},
      {"batch", lidarshop::cli::RunBatch, "a pipeline of commands over many scans (local or Dask cluster)"},
      {"steps", lidarshop::cli::RunSteps,
       "several commands one after the other in this process (batch's scans)"},
      {"schema", lidarshop::cli::RunSchema, "the editor's API structs as TypeScript or JSON descriptions"},
  };
  return commands;
}

void PrintUsage(std::FILE* stream) {
  fmt::print(stream, "lidarshop — edit terrestrial LiDAR scans\n\nUsage: lidarshop <command> [options]\n\n");
  fmt::print(stream, "Commands:\n");
  for (const Command& command : Commands())
    fmt::print(stream, "  {:<10} {}\n", command.name, command.summary);
  fmt::print(stream, "\n`lidarshop <command> --help` describes each command.\n");
}

// Large buffers on transparent huge pages: glibc's malloc does it with the tunable glibc.malloc.hugetlb=1, which
// it reads only when a process starts, so the process starts itself once more with it set. A station's channels
// are gigabytes touched once; in 4 KiB pages on the 2-core virtual machine of bench/results the first touch costs
// 3.5 s a GiB (a fresh 1 GiB memset; 0.05 s the second time), and `info --stats` of the 100 M-ray station took
// 34.9 s, 19.9 s with huge pages (docs/memory.md). Not done when GLIBC_TUNABLES is set already (the user's
// choice, and the second start) or LIDARSHOP_HUGE_PAGES=0; if the start fails, the command runs as it is.
void StartWithHugePages(char** argv) {
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35))
  if (std::getenv("GLIBC_TUNABLES") != nullptr) return;
  if (const char* wanted = std::getenv("LIDARSHOP_HUGE_PAGES");
      wanted != nullptr && std::strcmp(wanted, "0") == 0)
    return;
  if (setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1", 1) != 0) return;
  execv("/proc/self/exe", argv);
  unsetenv("GLIBC_TUNABLES");  // not started again: go on without
#else
  (void)argv;
#endif
}

}  // namespace

namespace lidarshop::cli {

int RunCommandLine(int argc, char** argv) {
  const std::string name = argc > 0 ? argv[0] : "";
  for (const Command& command : Commands()) {
    if (name != command.name) continue;
    // RunCommand turns every error into one line; this is the last resort for what escapes it (an allocation
    // failing while an error is reported, a command that does not use RunCommand).
    try {
      return command.run(argc, argv);
    } catch (const std::bad_alloc&) {
      fmt::print(stderr,
                 "lidarshop {}: out of memory: an allocation failed (memory budget {} MiB; --max-memory SIZE "
                 "makes large requests fail up front)\n",
                 name, MemoryBudgetBytes() >> 20);
      return kExitBadInput;
    } catch (const std::exception& error) {
      fmt::print(stderr, "lidarshop {}: {}\n", name, error.what());
      return kExitBadInput;
    }
  }
  fmt::print(stderr, "lidarshop: unknown command '{}' (lidarshop --help lists the commands)\n", name);
  return kExitUsage;
}

}  // namespace lidarshop::cli

int main(int argc, char** argv) {
  StartWithHugePages(argv);
  // Warnings go to stderr: stdout carries the JSON that scripts read (info, scan --stats).
  spdlog::set_default_logger(spdlog::stderr_color_mt("lidarshop"));
  if (argc < 2) {
    PrintUsage(stderr);
    return 2;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    PrintUsage(stdout);
    return 0;
  }
  if (name == "--version") {
    fmt::print("lidarshop 0.1.0\n");
    return 0;
  }
  return lidarshop::cli::RunCommandLine(argc - 1, argv + 1);
}
