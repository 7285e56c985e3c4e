// Atomic output: every file lidarshop writes first goes to a temporary file beside the target, which is
// renamed over the target only when writing succeeded. A crash or an error never leaves a half-written
// output, and an input is never opened for writing. A file that is replaced keeps its permission bits.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace lidarshop {

// Calls `write(stream)` on a binary stream to a temporary file in the target's folder, then renames
// it to `path`. Throws InputError naming `path` when the folder is not writable or the stream
// fails; the temporary is removed.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// For writers that need a path (OpenCV's imwrite, a C library): `write(temporary_path)` must create the file
// at temporary_path, which keeps the target's extension so that format detection still works; it is then
// renamed to `path`. `write` returns false (or throws) on failure.
void WritePathAtomically(const std::string& path, const std::function<bool(const std::string&)>& write);

// Checks an output path before any long work: its folder must exist, it must not be a folder, and it must not
// name the same file as any of `others` (the inputs, and the outputs already checked; empty strings are
// skipped). Throws OptionsError naming the path.
void CheckOutputPath(const std::string& path, const std::vector<std::string>& others);

}  // namespace lidarshop
