#include "lidarshop/util/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

std::string TemporaryPathFor(const std::string& path) {
  static std::atomic<int> counter{0};
  const std::filesystem::path target(path);
  const std::string name =
      fmt::format(".{}.tmp{}-{}{}", target.stem().string(), getpid(), counter++, target.extension().string());
  return (target.parent_path() / name).string();
}

void Commit(const std::string& temporary, const std::string& path) {
  std::error_code error;
  // A replaced file keeps its permissions (a private 600 scan must not become 644 by being rewritten).
  struct stat target {};
  if (stat(path.c_str(), &target) == 0 && S_ISREG(target.st_mode)) {
    chmod(temporary.c_str(), target.st_mode & 07777);
  }
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    ThrowInputError(path, "", "", "cannot write the file (rename failed)");
  }
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

void WritePathAtomically(const std::string& path, const std::function<bool(const std::string&)>& write) {
  if (path.empty()) ThrowInputError("", "", "", "empty output path");
  const std::string temporary = TemporaryPathFor(path);
  bool written = false;
  try {
    written = write(temporary);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
  if (!written || !std::filesystem::exists(temporary)) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    ThrowInputError(path, "", "", "cannot write the file (folder missing or not writable?)");
  }
  Commit(temporary, path);
}

void CheckOutputPath(const std::string& path, const std::vector<std::string>& others) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path target = fs::absolute(path, error);
  if (fs::is_directory(target, error)) throw OptionsError(fmt::format("{}: is a folder, not a file", path));
  const fs::path folder = target.parent_path();
  if (!fs::is_directory(folder, error)) {
    throw OptionsError(fmt::format("{}: the folder {} does not exist", path, folder.string()));
  }
  const fs::path canonical = fs::weakly_canonical(target, error);
  for (const std::string& other : others) {
    if (other.empty()) continue;
    const bool same_file =
        fs::exists(target, error) && fs::exists(other, error) && fs::equivalent(target, other, error);
    if (same_file || canonical == fs::weakly_canonical(fs::absolute(other, error), error)) {
      throw OptionsError(fmt::format("{}: the output would overwrite {}; choose another path", path, other));
    }
  }
}

}  // namespace lidarshop
