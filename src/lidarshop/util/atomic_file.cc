#include "lidarshop/util/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

namespace fs = std::filesystem;

// The temporary's name: ".STEM.tmpPID-N.EXT" (hidden, the target's extension kept for format detection), N a
// random 64-bit number: another user cannot guess it to plant a symlink there, and two writers of the same
// target (threads, or processes sharing a pid namespace's numbers on a network folder) never pick the same.
// lidarshop_batch.py and the server's file listing know this form.
constexpr std::string_view kTemporaryMark = ".tmp";

std::string WriteFailure(const fs::path& folder, int saved_errno);

uint64_t RandomNumber() {
  uint64_t value = 0;
  if (getrandom(&value, sizeof(value), 0) == static_cast<ssize_t>(sizeof(value))) return value;
  // No getrandom (an old kernel): a counter mixed with the clock, still never repeated within the process.
  static std::atomic<uint64_t> counter{0};
  return (static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) << 16) ^
         counter++;
}

// The process's umask, read without changing it (umask(2) can only be read by setting it, which would race
// with other threads creating files): the mode a new output gets, as if the writer had created it.
mode_t CurrentUmask() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::strtol(line.c_str() + 6, nullptr, 8));
  }
  return 022;
}

// Creates the temporary for `path` — O_CREAT | O_EXCL (never an existing file nor a symlink planted there),
// mode 0600 until it is complete — and returns its name. Throws InputError when the folder does not take it.
std::string CreateTemporaryFor(const std::string& path) {
  const fs::path target(path);
  for (int attempt = 0;; ++attempt) {
    const std::string name = fmt::format(".{}{}{}-{}{}", target.stem().string(), kTemporaryMark, getpid(),
                                         RandomNumber(), target.extension().string());
    const std::string temporary = (target.parent_path() / name).string();
    const int fd = open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd >= 0) {
      close(fd);
      return temporary;
    }
    if (errno != EEXIST || attempt >= 100) {
      fs::path folder = target.parent_path();
      if (folder.empty()) folder = ".";
      ThrowInputError(path, "", "", "cannot write the file: " + WriteFailure(folder, errno));
    }
  }
}

// The writer's pid when `name` is a temporary of ours for `target` (".STEM.tmpPID-N.EXT"), else 0.
pid_t TemporaryWriter(const std::string& name, const fs::path& target) {
  const std::string prefix = "." + target.stem().string() + std::string(kTemporaryMark);
  const std::string extension = target.extension().string();
  if (name.size() <= prefix.size() + extension.size() || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - extension.size(), extension.size(), extension) != 0) {
    return 0;
  }
  const std::string middle = name.substr(prefix.size(), name.size() - prefix.size() - extension.size());
  const size_t dash = middle.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == middle.size()) return 0;
  for (size_t i = 0; i < middle.size(); ++i) {
    if (i != dash && (middle[i] < '0' || middle[i] > '9')) return 0;
  }
  const long pid = std::strtol(middle.substr(0, dash).c_str(), nullptr, 10);
  return pid > 0 && pid < (1L << 30) ? static_cast<pid_t>(pid) : 0;
}

// Removes the temporaries a killed earlier write of `path` left beside it (`kill -9`, a power cut). Only
// names of our form for this very target are considered, and only when no writer can still own them: the
// writing process is gone on this machine and the file has not changed for a minute (a folder shared by
// several machines holds pids that are not ours to test), or the file has not changed for a day whatever its
// pid says (a pid reused since). A concurrent writer of the same target is alive and writing, so its
// temporary stays.
void RemoveStaleTemporaries(const std::string& path) {
  const fs::path target(path);
  fs::path folder = target.parent_path();
  if (folder.empty()) folder = ".";
  std::error_code error;
  const auto now = fs::file_time_type::clock::now();
  for (auto it = fs::directory_iterator(folder, error); !error && it != fs::directory_iterator();
       it.increment(error)) {
    const pid_t writer = TemporaryWriter(it->path().filename().string(), target);
    if (writer == 0 || writer == getpid()) continue;
    std::error_code status_error;
    if (!it->is_regular_file(status_error) || it->is_symlink(status_error)) continue;
    const auto modified = it->last_write_time(status_error);
    if (status_error) continue;
    const auto age = now - modified;
    const bool writer_gone = kill(writer, 0) != 0 && errno == ESRCH;
    if ((writer_gone && age > std::chrono::minutes(1)) || age > std::chrono::hours(24)) {
      fs::remove(it->path(), status_error);
    }
  }
}

// Why writing into `folder` failed, for the message: a full disk is said as such (errno from the failed
// write, or the file system's free blocks when a library swallowed errno).
std::string WriteFailure(const fs::path& folder, int saved_errno) {
  struct statvfs space {};
  const bool full = saved_errno == ENOSPC || saved_errno == EDQUOT ||
                    (statvfs(folder.c_str(), &space) == 0 && space.f_bavail == 0);
  if (full) return "no space left on device";
  std::error_code error;
  if (!fs::is_directory(folder, error)) return fmt::format("the folder {} does not exist", folder.string());
  if (access(folder.c_str(), W_OK) != 0) return fmt::format("the folder {} is not writable", folder.string());
  if (saved_errno != 0) return std::strerror(saved_errno);
  return "the writer failed";
}

void Commit(const std::string& temporary, const std::string& path) {
  std::error_code error;
  // A replaced file keeps its permissions (a private 600 scan must not become 644 by being rewritten); a new
  // one gets what the umask gives a created file (the temporary was 0600 while it was written).
  struct stat target {};
  if (stat(path.c_str(), &target) == 0 && S_ISREG(target.st_mode)) {
    chmod(temporary.c_str(), target.st_mode & 07777);
  } else {
    chmod(temporary.c_str(), 0666 & ~CurrentUmask());
  }
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    ThrowInputError(path, "", "", "cannot write the file (rename failed)");
  }
}

std::mutex& ProtectedMutex() {
  static std::mutex mutex;
  return mutex;
}

std::vector<std::string>& ProtectedInputs() {
  static std::vector<std::string> inputs;
  return inputs;
}

// The protected input `path` would overwrite, or empty.
std::string ProtectedInputAt(const std::string& path) {
  std::lock_guard lock(ProtectedMutex());
  std::error_code error;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(path, error), error);
  for (const std::string& input : ProtectedInputs()) {
    const bool same_file =
        fs::exists(path, error) && fs::exists(input, error) && fs::equivalent(path, input, error);
    if (same_file || canonical == fs::weakly_canonical(fs::absolute(input, error), error)) return input;
  }
  return "";
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  WritePathAtomically(path, [&](const std::string& temporary) {
    std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
    if (!stream) return false;
    write(stream);
    stream.flush();
    return static_cast<bool>(stream);
  });
}

void WriteTextAtomically(const std::string& path, const std::string& text) {
  WriteFileAtomically(path, [&](std::ostream& stream) { stream << text; });
}

void WritePathAtomically(const std::string& path, const std::function<bool(const std::string&)>& write) {
  if (path.empty()) ThrowInputError("", "", "", "empty output path");
  const std::string input = ProtectedInputAt(path);
  if (!input.empty())
    ThrowInputError(path, "", "", fmt::format("the output would overwrite the input {}", input));
  RemoveStaleTemporaries(path);
  const std::string temporary = CreateTemporaryFor(path);
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  bool written = false;
  errno = 0;
  try {
    written = write(temporary);
  } catch (...) {
    // Asked before the temporary is removed, which frees the space it took.
    const std::string why = WriteFailure(folder, errno);
    std::error_code ignored;
    fs::remove(temporary, ignored);
    // A full disk is the one cause worth saying over whatever the writer made of it.
    if (why == "no space left on device") ThrowInputError(path, "", "", "cannot write the file: " + why);
    throw;
  }
  std::error_code exists_error;
  if (!written || !fs::exists(temporary, exists_error)) {
    const std::string why = WriteFailure(folder, errno);
    std::error_code ignored;
    fs::remove(temporary, ignored);
    ThrowInputError(path, "", "", "cannot write the file: " + why);
  }
  Commit(temporary, path);
}

void ProtectInput(const std::string& path) {
  std::lock_guard lock(ProtectedMutex());
  ProtectedInputs().push_back(path);
}

void ForgetProtectedInputs() {
  std::lock_guard lock(ProtectedMutex());
  ProtectedInputs().clear();
}

bool IsAtomicTemporary(const std::string& name) {
  // ".STEM.tmpPID-N.EXT" or ".STEM.tmpPID-N" (a target without extension).
  if (name.empty() || name[0] != '.') return false;
  const size_t mark = name.rfind(kTemporaryMark);
  if (mark == std::string::npos) return false;
  size_t i = mark + kTemporaryMark.size();
  const size_t digits_start = i;
  while (i < name.size() && name[i] >= '0' && name[i] <= '9') ++i;
  if (i == digits_start || i >= name.size() || name[i] != '-') return false;
  const size_t counter_start = ++i;
  while (i < name.size() && name[i] >= '0' && name[i] <= '9') ++i;
  return i > counter_start && (i == name.size() || name[i] == '.');
}

void CheckOutputPath(const std::string& path, const std::vector<std::string>& others) {
  std::error_code error;
  const fs::path target = fs::absolute(path, error);
  if (fs::is_directory(target, error)) throw OptionsError(fmt::format("{}: is a folder, not a file", path));
  const fs::path folder = target.parent_path();
  if (!fs::is_directory(folder, error)) {
    throw OptionsError(fmt::format("{}: the folder {} does not exist", path, folder.string()));
  }
  const fs::path canonical = fs::weakly_canonical(target, error);
  std::vector<std::string> all = others;
  {
    std::lock_guard lock(ProtectedMutex());
    all.insert(all.end(), ProtectedInputs().begin(), ProtectedInputs().end());
  }
  for (const std::string& other : all) {
    if (other.empty()) continue;
    const bool same_file =
        fs::exists(target, error) && fs::exists(other, error) && fs::equivalent(target, other, error);
    if (same_file || canonical == fs::weakly_canonical(fs::absolute(other, error), error)) {
      throw OptionsError(fmt::format("{}: the output would overwrite {}; choose another path", path, other));
    }
  }
}

}  // namespace lidarshop
