// The command table of the `lidarshop` executable. Each command group lives in its own file and exposes
// `int RunX(int argc, char** argv)` where argv[0] is the command's name (e.g. "scan").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop::cli {

int RunScan(int argc, char** argv);       // scan_command.cc
int RunInfo(int argc, char** argv);       // file_commands.cc
int RunConvert(int argc, char** argv);    // file_commands.cc
int RunFormats(int argc, char** argv);    // formats_command.cc
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
int RunRegister(int argc, char** argv);   // register_command.cc
int RunClean(int argc, char** argv);      // clean_command.cc
int RunBatch(int argc, char** argv);      // batch_command.cc
int RunServe(int argc, char** argv);      // serve_command.cc
int RunSchema(int argc, char** argv);     // schema_command.cc

class OptionBinder;

// Exit codes of every command (README "Exit codes").
inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 1;  // input data: a file that does not parse, a missing channel
inline constexpr int kExitUsage = 2;     // usage: unknown option, bad value, missing argument

// Parses argv with `app` and runs `body`, turning every exception into one line on stderr
// ("lidarshop scan: <message>"): usage errors (CLI11's, OptionsError, an unknown option with the closest valid
// one) exit with kExitUsage, everything else (InputError, a library's exception) with kExitBadInput. With a
// `binder`, option errors name the flag the user typed.
// Every command takes -q/--quiet and --max-memory (added here when the command did not add them). When the body
// succeeds and set a summary (Summarize), RunCommand ends with it as one line on stderr, with the wall time:
// "lidarshop fill: filled 812 of 840 hole cells (3.21 s)"; not with --quiet. On errors the one error line is
// all that stderr gets.
int RunCommand(CLI::App& app, int argc, char** argv, const std::function<int()>& body,
               const OptionBinder* binder = nullptr);

// The command's one-line summary for people: what it changed and how much (RunCommand adds the time). The
// last call wins. A command without one (serve) ends without.
void Summarize(std::string what);
// The warnings of a result (SegmentResult::warnings, FillResult::warnings, ...: the result looks wrong), one
// line each on stderr ("lidarshop segment: warning: <sentence>"), also with --quiet: they say the output may
// be wrong. The same sentences go into the command's --json "warnings".
void PrintResultWarnings(const std::vector<std::string>& warnings);

// Adds --json FILE ('-' = stdout): where the command's result goes as JSON. Machine output goes only there;
// summaries for people go to stderr.
// `names` may add a command's older name for it ("--json,--report").
// Commands whose JSON went to stdout before --json existed (info, images, resection, recolor, align) start
// with *path = "-".
CLI::Option* AddJsonOption(CLI::App& app, std::string* path, const std::string& names = "--json");
// What every command's --json ends with: the options it ran with (the JSON form of its options struct, or of
// several: `register` with several MOVING gives RegisterSiteOptions').
struct CommandOptions {
  nlohmann::ordered_json options;
};
// The JSON form of a command's run: the result's keys, then CommandOptions' "options".
nlohmann::ordered_json CommandJson(const nlohmann::ordered_json& options,
                                   const nlohmann::ordered_json& result);
// Writes `json` to `path` ("-" = stdout, else atomically); nothing when `path` is empty. `indent` -1 = one line.
// `inline_arrays`: arrays of numbers and strings on one line ("[1, 0, 0, 0]"), for output people read.
void WriteJsonOutput(const std::string& path, const nlohmann::ordered_json& json, int indent = 2,
                     bool inline_arrays = false);
// `json` indented by `indent`, arrays of scalars on one line.
std::string DumpWithInlineArrays(const nlohmann::ordered_json& json, int indent, int depth = 0);

// Checks an output before any long work: its extension is one of `extensions` (lower case, no dot;
// empty = any), its folder exists and is writable, and it names no input or other output. Throws
// OptionsError naming `flag`.
void CheckOutputFile(const std::string& flag, const std::string& path,
                     const std::vector<std::string>& extensions, const std::vector<std::string>& others);

// Prints a reader's warnings on stderr, one line each ("lidarshop: warning: <file>: <what was left out>").
void PrintWarnings(const std::vector<std::string>& warnings);
// ReadScanFile, ReadE57 and ReadMeshFile for commands: the reader's warnings are printed (PrintWarnings).
ScanFile ReadScanFileAndWarn(const std::string& path);
E57File ReadE57AndWarn(const std::string& path);
TriangleMesh ReadMeshAndWarn(const std::string& path);

// Scan `index` of `file`; OptionsError naming `flag` (the option the user typed) when out of range.
const Scan& PickScan(const ScanFile& file, int index, const std::string& flag = "--scan");

// Adds --scan K (which scan of a multi-scan file, from 0) and --scan-index, its older name, both into *index:
// one flag for the scan index in every command that reads one scan (render, convert, segment, fill, remove,
// recolor). `resection` is the exception: its --scan names a scan FILE, so its index stays --scan-index.
void AddScanIndexOption(CLI::App& app, int* index,
                        const std::string& help = "which scan of the file (from 0)");
// The scan index flag the user typed ("--scan" unless --scan-index), for PickScan's message.
std::string ScanIndexFlag(const CLI::App& app);

// Adds -q/--quiet (no progress bars, no summary line) to `app`; the flag is stored in *quiet. Also adds --max-memory SIZE
// ("512M", "8G"; default half of the RAM), which sets the memory budget (util/memory_budget.h) that
// header counts, scene complexity, sample and sweep counts are checked against before any allocation.
void AddQuietFlag(CLI::App& app, bool* quiet);
// Adds --max-memory SIZE alone; RunCommand adds it to every command that has not.
void AddMemoryOption(CLI::App& app);

// Adds a --seed option storing into *seed: a whole number in [0, 2^63) (CLI11 alone would
// wrap "-1" to the largest seed).
void AddSeedOption(CLI::App& app, uint64_t* seed, const std::string& help);

}  // namespace lidarshop::cli

namespace lidarshop {
template <>
const StructInfo& InfoOf<cli::CommandOptions>();  // common.cc
}  // namespace lidarshop
