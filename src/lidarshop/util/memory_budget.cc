#include "lidarshop/util/memory_budget.h"

#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

int64_t DefaultBudgetBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGESIZE);
  const int64_t physical = pages > 0 && page_size > 0 ? int64_t{pages} * page_size : int64_t{4} << 30;
  return std::max<int64_t>(physical / 2, int64_t{1} << 30);
}

std::atomic<int64_t>& Budget() {
  static std::atomic<int64_t> budget{DefaultBudgetBytes()};
  return budget;
}

}  // namespace

int64_t MemoryBudgetBytes() { return Budget().load(); }

void SetMemoryBudgetBytes(int64_t bytes) {
  CheckOption(bytes > 0, fmt::format("the memory budget must be > 0 bytes, got {}", bytes));
  Budget().store(bytes);
}

void CheckMemoryBudget(int64_t bytes, std::string_view what) {
  const int64_t budget = MemoryBudgetBytes();
  if (bytes >= 0 && bytes <= budget) return;
  // Rounded up without adding to `bytes`, which may be INT64_MAX (a saturated request).
  const std::string needed = bytes < 0
                                 ? std::string("more than 8 EiB")
                                 : fmt::format("about {} MiB", bytes / (1 << 20) + (bytes % (1 << 20) != 0));
  throw InputError(fmt::format("{} needs {}, more than the memory budget of {} MiB (--max-memory)", what,
                               needed, budget >> 20));
}

int64_t SaturatingBytes(int64_t count, int64_t bytes_each) {
  if (count <= 0 || bytes_each <= 0) return 0;
  if (count > std::numeric_limits<int64_t>::max() / bytes_each) return std::numeric_limits<int64_t>::max();
  return count * bytes_each;
}

int64_t ParseMemorySize(const std::string& text, std::string_view option) {
  char* end = nullptr;
  const double number = std::strtod(text.c_str(), &end);
  std::string unit(end);
  for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  double scale = 0;
  if (unit.empty() || unit == "B") scale = 1;
  if (unit == "K" || unit == "KB" || unit == "KIB") scale = 1024.0;
  if (unit == "M" || unit == "MB" || unit == "MIB") scale = 1024.0 * 1024;
  if (unit == "G" || unit == "GB" || unit == "GIB") scale = 1024.0 * 1024 * 1024;
  if (unit == "T" || unit == "TB" || unit == "TIB") scale = 1024.0 * 1024 * 1024 * 1024;
  const double bytes = number * scale;
  CheckOption(end != text.c_str() && scale > 0 && std::isfinite(bytes) && bytes >= 1 << 20 && bytes < 0x1p62,
              fmt::format("{}: '{}' is not a memory size from 1M to 4E (e.g. 512M, 8G)", option, text));
  return static_cast<int64_t>(bytes);
}

}  // namespace lidarshop
