// The memory budget of one run: work whose size is known up front (a grid a header claims, triangles after
// subdivision, a texture, a sweep's poses, a sample count) is checked against it before anything is
// allocated, so a request past it becomes one clear error instead of an allocation failure minutes later.
// The CLI sets it from `--max-memory`; the default is half of the physical memory.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace lidarshop {

// The budget in bytes (default: half of the physical memory, at least 1 GiB).
int64_t MemoryBudgetBytes();

// Sets the budget; `bytes` must be > 0 (OptionsError otherwise).
void SetMemoryBudgetBytes(int64_t bytes);

// Throws InputError "<what> needs about X MiB, more than the memory budget of Y MiB (--max-memory)" when
// `bytes` (negative = overflowed) exceeds the budget.
void CheckMemoryBudget(int64_t bytes, std::string_view what);

// `count * bytes_each`, saturated at INT64_MAX (counts from hostile input must not overflow).
int64_t SaturatingBytes(int64_t count, int64_t bytes_each);

// Parses "512M", "4G", "1.5GiB", "800000" (bytes) into bytes; throws OptionsError naming `option`.
int64_t ParseMemorySize(const std::string& text, std::string_view option);

}  // namespace lidarshop
