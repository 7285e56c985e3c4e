// Only regular files are read: FIFOs, folders and devices are refused from their stat, without blocking.
#include "lidarshop/util/input_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

using testing::HasSubstr;

std::string InputFileFolder() {
  const std::string folder =
      std::filesystem::temp_directory_path() / ("input_file_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(folder);
  return folder;
}

std::string ErrorOf(const std::string& path) {
  try {
    ReadRegularFile(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(InputFileTest, ReadsARegularFile) {
  const std::string path = InputFileFolder() + "/a.txt";
  std::ofstream(path) << "hello";
  EXPECT_EQ(CheckRegularFile(path), 5);
  EXPECT_EQ(ReadRegularFile(path), "hello");
  EXPECT_THAT(ErrorOf(path + ".missing"), HasSubstr("cannot open"));
}

TEST(InputFileTest, RefusesAFifoWithoutBlocking) {
  const std::string path = InputFileFolder() + "/x.ptx";
  std::filesystem::remove(path);
  ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
  // Opening a FIFO for reading waits for a writer: run on a thread so that a regression fails, not hangs.
  auto message = std::async(std::launch::async, [&] { return ErrorOf(path); });
  ASSERT_EQ(message.wait_for(std::chrono::seconds(10)), std::future_status::ready)
      << "reading a FIFO blocked";
  EXPECT_THAT(message.get(), HasSubstr("named pipe"));
  std::filesystem::remove(path);
}

TEST(InputFileTest, RefusesFoldersAndDevices) {
  const std::string folder = InputFileFolder() + "/scan.ptx";
  std::filesystem::create_directories(folder);
  EXPECT_THAT(ErrorOf(folder), HasSubstr("is a folder"));
  EXPECT_THAT(ErrorOf("/dev/zero"), HasSubstr("device"));
  EXPECT_THAT(ErrorOf(""), HasSubstr("empty input path"));
}

TEST(InputFileTest, RefusesFilesPastTheLimit) {
  const std::string path = InputFileFolder() + "/big.json";
  std::ofstream(path) << std::string(100, 'x');
  EXPECT_THROW(ReadRegularFile(path, 99), InputError);
  EXPECT_EQ(ReadRegularFile(path, 100).size(), 100u);
}

TEST(MemoryBudgetTest, ChecksRequestsAgainstTheBudget) {
  const int64_t before = MemoryBudgetBytes();
  EXPECT_GE(before, int64_t{1} << 30);
  SetMemoryBudgetBytes(int64_t{64} << 20);
  EXPECT_NO_THROW(CheckMemoryBudget(int64_t{64} << 20, "test"));
  try {
    CheckMemoryBudget(int64_t{65} << 20, "a grid");
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("a grid needs about 65 MiB, more than the memory budget of 64 MiB"));
  }
  EXPECT_THROW(CheckMemoryBudget(SaturatingBytes(int64_t{1} << 40, int64_t{1} << 40), "overflow"),
               InputError);
  EXPECT_THROW(SetMemoryBudgetBytes(0), OptionsError);
  SetMemoryBudgetBytes(before);
}

TEST(MemoryBudgetTest, ParsesSizes) {
  EXPECT_EQ(ParseMemorySize("512M", "--max-memory"), int64_t{512} << 20);
  EXPECT_EQ(ParseMemorySize("8G", "--max-memory"), int64_t{8} << 30);
  EXPECT_EQ(ParseMemorySize("1.5GiB", "--max-memory"), int64_t{3} << 29);
  for (const char* bad : {"", "abc", "-1G", "1X", "inf", "nan", "1", "1e30G"}) {
    EXPECT_THROW(ParseMemorySize(bad, "--max-memory"), OptionsError) << bad;
  }
}

}  // namespace
}  // namespace lidarshop
