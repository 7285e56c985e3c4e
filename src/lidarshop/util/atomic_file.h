// Atomic output: every file lidarshop writes first goes to a temporary file beside the target, which is
// renamed over the target only when writing succeeded. A crash or an error never leaves a half-written
// output, and an input is never opened for writing. A file that is replaced keeps its permission bits; a new
// one gets those the umask gives. The temporary's name holds a random number and it is created with O_EXCL,
// mode 0600, before the writer opens it: a name planted beforehand (a symlink another user made) is never
// followed, and concurrent writers of one target never share a temporary.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace lidarshop {

// Calls `write(stream)` on a binary stream to a temporary file in the target's folder, then renames
// it to `path`. Throws InputError naming `path` and the cause ("no space left on device", "the folder ... is
// not writable") when the stream fails, and when `path` is a protected input (ProtectInput); the temporary is
// removed. Temporaries of an earlier write of the same target whose writer is gone (killed) are removed first.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// WriteFileAtomically of `text`, as it is.
void WriteTextAtomically(const std::string& path, const std::string& text);

// For writers that need a path (OpenCV's imwrite, a C library): `write(temporary_path)` must create the file
// at temporary_path, which keeps the target's extension so that format detection still works; it is then
// renamed to `path`. `write` returns false (or throws) on failure.
void WritePathAtomically(const std::string& path, const std::function<bool(const std::string&)>& write);

// Checks an output path before any long work: its folder must exist, it must not be a folder, and it must not
// name the same file as any of `others` (the inputs, and the outputs already checked; empty strings are
// skipped). Throws OptionsError naming the path.
// The protected inputs (ProtectInput) count among `others`.
void CheckOutputPath(const std::string& path, const std::vector<std::string>& others);

// Marks `path` as an input of this process that no output may replace (the CLI's --options file): every later
// CheckOutputPath refuses it, and WriteFileAtomically / WritePathAtomically refuse to write over it.
void ProtectInput(const std::string& path);
// Forgets every protected input: for a process that runs several commands one after another (`lidarshop
// steps`), each with inputs of its own.
void ForgetProtectedInputs();

// True when `name` (a file name, no folder) has the form of a temporary of an atomic write
// (".STEM.tmpPID-N.EXT"): listings of files for people (the server's file dialog) leave these out.
bool IsAtomicTemporary(const std::string& name);

}  // namespace lidarshop
