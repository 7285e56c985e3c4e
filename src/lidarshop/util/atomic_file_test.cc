// Atomic outputs keep the permissions of the file they replace and refuse an output equal to an input.
#include "lidarshop/util/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

std::string Folder() {
  const std::string folder =
      std::filesystem::temp_directory_path() / ("atomic_file_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(folder);
  return folder;
}

mode_t ModeOf(const std::string& path) {
  struct stat status {};
  EXPECT_EQ(stat(path.c_str(), &status), 0);
  return status.st_mode & 07777;
}

TEST(AtomicFileTest, OverwritingKeepsThePermissions) {
  const std::string path = Folder() + "/private.ptx";
  std::ofstream(path) << "old";
  ASSERT_EQ(chmod(path.c_str(), 0600), 0);
  WriteFileAtomically(path, [](std::ostream& out) { out << "new"; });
  EXPECT_EQ(ModeOf(path), 0600u);
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  EXPECT_EQ(text.str(), "new");
  ASSERT_EQ(chmod(path.c_str(), 0640), 0);
  WritePathAtomically(
      path, [](const std::string& temporary) { return static_cast<bool>(std::ofstream(temporary) << "x"); });
  EXPECT_EQ(ModeOf(path), 0640u);
}

TEST(AtomicFileTest, AFailedWriteLeavesNoFile) {
  const std::string path = Folder() + "/never.ply";
  std::filesystem::remove(path);
  EXPECT_THROW(WriteFileAtomically(path, [](std::ostream&) { throw InputError("midway"); }), InputError);
  EXPECT_FALSE(std::filesystem::exists(path));
  for (const auto& entry : std::filesystem::directory_iterator(Folder())) {
    EXPECT_EQ(entry.path().string().find(".never.tmp"), std::string::npos) << entry.path();
  }
}

TEST(AtomicFileTest, AnOutputEqualToAnInputIsRefused) {
  const std::string folder = Folder();
  const std::string input = folder + "/scan.ptx";
  std::ofstream(input) << "scan";
  EXPECT_THROW(CheckOutputPath(input, {input}), OptionsError);
  EXPECT_THROW(CheckOutputPath(folder + "/./scan.ptx", {input}), OptionsError);
  EXPECT_THROW(CheckOutputPath(folder + "/a.ply", {input, folder + "/a.ply"}), OptionsError);
  EXPECT_THROW(CheckOutputPath(folder, {}), OptionsError);
  EXPECT_THROW(CheckOutputPath(folder + "/missing/a.ply", {}), OptionsError);
  EXPECT_NO_THROW(CheckOutputPath(folder + "/b.ply", {input, ""}));
}

}  // namespace
}  // namespace lidarshop
