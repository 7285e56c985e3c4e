// The command table of the `lidarshop` executable. Each command group lives in its own file and exposes
// `int RunX(int argc, char** argv)` where argv[0] is the command's name (e.g. "scan").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/scan_io.h"

namespace lidarshop::cli {

int RunScan(int argc, char** argv);       // scan_command.cc
int RunInfo(int argc, char** argv);       // file_commands.cc
int RunConvert(int argc, char** argv);    // file_commands.cc
int RunRender(int argc, char** argv);     // file_commands.cc
int RunDemo(int argc, char** argv);       // demo_command.cc
int RunVerify(int argc, char** argv);     // verify_commands.cc
int RunSweep(int argc, char** argv);      // verify_commands.cc
int RunSegment(int argc, char** argv);    // segment_command.cc
int RunInpaint(int argc, char** argv);    // inpaint_command.cc
int RunPoisson(int argc, char** argv);    // poisson_command.cc
int RunFill(int argc, char** argv);       // fill_command.cc
int RunRemove(int argc, char** argv);     // fill_command.cc
int RunResection(int argc, char** argv);  // recolor_commands.cc
int RunRecolor(int argc, char** argv);    // recolor_commands.cc
int RunImages(int argc, char** argv);     // recolor_commands.cc
int RunAlign(int argc, char** argv);      // recolor_commands.cc
int RunPhoto(int argc, char** argv);      // recolor_commands.cc
int RunPoints(int argc, char** argv);     // points_command.cc
int RunRegister(int argc, char** argv);   // points_command.cc

// The images2D entries of an E57 file as JSON (name, size, representation, pose, intrinsics); `images` and
// `info` print it. recolor_commands.cc.
nlohmann::ordered_json ImagesJson(const std::vector<E57Image>& images);

// Parses argv with `app` and runs `body`, turning every exception into one line on stderr
// ("lidarshop scan: <message>") and exit code 1; CLI11 parse errors print CLI11's message and its exit code.
int RunCommand(CLI::App& app, int argc, char** argv, const std::function<int()>& body);

// Scan `index` of `file`; OptionsError naming `flag` (the option the user typed) when out of range.
const Scan& PickScan(const ScanFile& file, int index, const std::string& flag = "--scan-index");

// Adds --quiet (no progress bars) to `app`; the flag is stored in *quiet. Also adds --max-memory SIZE
// ("512M", "8G"; default half of the RAM), which sets the memory budget (util/memory_budget.h) that
// header counts, scene complexity, sample and sweep counts are checked against before any allocation.
void AddQuietFlag(CLI::App& app, bool* quiet);

// Adds a --seed option storing into *seed: a whole number in [0, 2^63) (CLI11 alone would wrap "-1" to the
// largest seed).
void AddSeedOption(CLI::App& app, uint64_t* seed, const std::string& help);

}  // namespace lidarshop::cli
