// Atomic outputs keep the permissions of the file they replace, refuse an output equal to an input (or to a
// protected input), clean the temporaries of killed writers and say when the disk is full.
#include "lidarshop/util/atomic_file.h"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
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

TEST(AtomicFileTest, AProtectedInputIsNeverOverwritten) {
  const std::string folder = Folder();
  const std::string options = folder + "/options.json";
  std::ofstream(options) << "{}";
  ProtectInput(options);
  EXPECT_THROW(CheckOutputPath(folder + "/./options.json", {}), OptionsError);
  EXPECT_THROW(WriteFileAtomically(options, [](std::ostream& out) { out << "report"; }), InputError);
  std::stringstream text;
  text << std::ifstream(options).rdbuf();
  EXPECT_EQ(text.str(), "{}");
  // The next command of the same process (`lidarshop steps`) has inputs of its own.
  ForgetProtectedInputs();
  EXPECT_NO_THROW(CheckOutputPath(folder + "/./options.json", {}));
}

TEST(AtomicFileTest, TheTemporariesOfDeadWritersAreRemovedAndOnlyThose) {
  namespace fs = std::filesystem;
  const std::string folder = Folder();
  // A pid that is surely gone: a child that exited and was reaped.
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_GT(child, 0);
  waitpid(child, nullptr, 0);
  const auto old = fs::file_time_type::clock::now() - std::chrono::minutes(5);
  auto make = [&](const std::string& name, bool aged) {
    const std::string path = folder + "/" + name;
    std::ofstream(path) << "half";
    if (aged) fs::last_write_time(path, old);
    return path;
  };
  const std::string dead_old = make(fmt::format(".out.tmp{}-0.ply", child), true);
  const std::string dead_fresh = make(fmt::format(".out.tmp{}-1.ply", child), false);  // maybe another host's
  const std::string alive_old = make(fmt::format(".out.tmp{}-2.ply", getppid()), true);  // a live writer
  const std::string other_target = make(fmt::format(".other.tmp{}-0.ply", child), true);
  const std::string not_ours = make(fmt::format(".out.tmp{}-x.ply", child), true);
  WriteFileAtomically(folder + "/out.ply", [](std::ostream& out) { out << "whole"; });
  EXPECT_FALSE(fs::exists(dead_old));
  for (const std::string& kept : {dead_fresh, alive_old, other_target, not_ours})
    EXPECT_TRUE(fs::exists(kept)) << kept;
  EXPECT_TRUE(IsAtomicTemporary(fs::path(dead_fresh).filename().string()));
  EXPECT_TRUE(IsAtomicTemporary(".scan.tmp12-3"));
  EXPECT_FALSE(IsAtomicTemporary(fs::path(not_ours).filename().string()));
  EXPECT_FALSE(IsAtomicTemporary("scan.tmp12-3.ply"));
  EXPECT_FALSE(IsAtomicTemporary(".tmp12.ply"));
  for (const std::string& path : {dead_fresh, alive_old, other_target, not_ours}) fs::remove(path);
}

// Another user of a shared folder plants symlinks at the temporary names a writer would pick (the old names
// were ".STEM.tmpPID-N.EXT" with N counting from 0): the write must neither follow them into the victim's
// file nor rename one of them over the output.
TEST(AtomicFileTest, APlantedSymlinkIsNeverFollowed) {
  namespace fs = std::filesystem;
  const std::string folder = Folder() + "/planted";
  fs::remove_all(folder);
  fs::create_directories(folder);
  const std::string victim = Folder() + "/victim.txt";
  std::ofstream(victim) << "the victim's own";
  std::vector<std::string> planted;
  for (int n = 0; n < 1000; ++n) {
    planted.push_back(fmt::format("{}/.out.tmp{}-{}.ply", folder, getpid(), n));
    fs::create_symlink(victim, planted.back());
  }
  const std::string output = folder + "/out.ply";
  for (int i = 0; i < 3; ++i) WriteFileAtomically(output, [](std::ostream& out) { out << "whole"; });
  std::stringstream victim_text, output_text;
  victim_text << std::ifstream(victim).rdbuf();
  output_text << std::ifstream(output).rdbuf();
  EXPECT_EQ(victim_text.str(), "the victim's own");
  EXPECT_FALSE(fs::is_symlink(output));
  EXPECT_EQ(output_text.str(), "whole");
  for (const std::string& link : planted) EXPECT_TRUE(fs::is_symlink(link)) << link;
  fs::remove_all(folder);
  fs::remove(victim);
}

// The temporary is the writer's alone from the start: created (O_EXCL) at mode 0600 before the writer
// opens it, under a name nobody can guess; the finished file gets the umask's mode.
TEST(AtomicFileTest, TheTemporaryIsPrivateAndUnpredictable) {
  namespace fs = std::filesystem;
  const std::string output = Folder() + "/private.ply";
  fs::remove(output);
  const mode_t old_umask = umask(022);
  std::vector<std::string> names;
  for (int i = 0; i < 2; ++i) {
    WritePathAtomically(output, [&](const std::string& temporary) {
      struct stat status {};
      EXPECT_EQ(lstat(temporary.c_str(), &status), 0);
      EXPECT_TRUE(S_ISREG(status.st_mode));
      EXPECT_EQ(status.st_mode & 07777, 0600u);
      EXPECT_TRUE(IsAtomicTemporary(fs::path(temporary).filename().string())) << temporary;
      names.push_back(temporary);
      std::ofstream(temporary) << "data";
      return true;
    });
  }
  umask(old_umask);
  EXPECT_EQ(ModeOf(output), 0644u);
  ASSERT_EQ(names.size(), 2u);
  // Not a counter: the two names differ in more than their last digit.
  EXPECT_GT(names[0].size() + names[1].size(), 2 * fmt::format(".private.tmp{}-0.ply", getpid()).size() + 20);
  fs::remove(output);
}

// Writers of one target at once (threads here): each write is whole, none fails, no temporary is left.
TEST(AtomicFileTest, ConcurrentWritersOfOneTargetDoNotCollide) {
  namespace fs = std::filesystem;
  const std::string folder = Folder() + "/concurrent";
  fs::remove_all(folder);
  fs::create_directories(folder);
  const std::string output = folder + "/shared.ply";
  std::atomic<int> failures{0};
  std::vector<std::thread> writers;
  for (int k = 0; k < 4; ++k) {
    writers.emplace_back([&, k] {
      for (int i = 0; i < 50; ++i) {
        try {
          WriteFileAtomically(
              output, [k](std::ostream& out) { out << std::string(20000, static_cast<char>('a' + k)); });
        } catch (const std::exception&) {
          ++failures;
        }
      }
    });
  }
  for (std::thread& writer : writers) writer.join();
  EXPECT_EQ(failures, 0);
  std::stringstream text;
  text << std::ifstream(output).rdbuf();
  ASSERT_EQ(text.str().size(), 20000u);
  EXPECT_EQ(text.str(), std::string(20000, text.str()[0]));
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(folder)) ++files;
  EXPECT_EQ(files, 1);  // no temporary left behind
  fs::remove_all(folder);
}

TEST(AtomicFileTest, AFullDiskIsSaidAsSuch) {
  // /dev/full fails every write with ENOSPC; the stream's failure is reported with that cause.
  const std::string path = Folder() + "/full.ply";
  try {
    WritePathAtomically(path, [](const std::string&) {
      std::ofstream full("/dev/full", std::ios::binary);
      full << std::string(1 << 16, 'x');
      full.flush();
      return static_cast<bool>(full);
    });
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("no space left on device"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("full.ply"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace lidarshop
