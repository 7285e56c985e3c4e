// Small helpers shared by the io tests: a temporary folder and file writing.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop::testing_io {

// A fresh folder under the system temp folder, removed when the object dies.
class TempFolder {
 public:
  TempFolder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / (std::string("lidarshop_") + info->test_suite_name() +
                                                      "_" + info->name() + "_" + std::to_string(getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempFolder() { std::filesystem::remove_all(path_); }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// The message of the InputError that `read` throws ("" when nothing is thrown).
inline std::string InputErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// The message of the InputError that reading `path` as a scan file throws ("" when it reads).
inline std::string ScanError(const std::string& path) {
  return InputErrorOf([&] { ReadScanFile(path); });
}

// The shared E57 files (../shared/data/e57, SOURCES.md there).
inline const std::string kE57Dir = LIDARSHOP_SHARED_DATA_DIR "/e57/";

inline void WriteText(const std::string& path, const std::string& text) {
  std::ofstream stream(path, std::ios::binary);
  stream.write(text.data(), static_cast<std::streamsize>(text.size()));
}

inline std::string ReadText(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

}  // namespace lidarshop::testing_io
