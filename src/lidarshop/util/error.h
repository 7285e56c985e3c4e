// Errors of lidarshop.
//
// Two kinds, both exceptions so that no caller can ignore them:
//  * InputError   — the data given to us is wrong (a file that does not parse, a mask of the wrong size). The
//                   message names the file, the place (line, byte offset, page) and the field, so a user can
//                   fix the input: "scan.ptx: line 12: field 'x': not a number: 'abc'".
//  * OptionsError — a parameter is out of its documented range ("VerifyOptions.sigma_m must be > 0, got -1").
// Broken internal invariants are bugs and use LIDARSHOP_CHECK, which throws
// std::logic_error with file and line.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace lidarshop {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class OptionsError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// An operation stopped by its caller (Progress::Cancel), not a failure.
class CancelledError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Builds "<file>: <place>: field '<field>': <message>", leaving out empty parts.
std::string FormatInputError(std::string_view file, std::string_view place, std::string_view field,
                             std::string_view message);

// Throws InputError with FormatInputError's message.
[[noreturn]] void ThrowInputError(std::string_view file, std::string_view place, std::string_view field,
                                  std::string_view message);

// Throws OptionsError unless `condition`; the message should name the struct, the field and the value.
inline void CheckOption(bool condition, std::string_view message) {
  if (!condition) throw OptionsError(std::string(message));
}

}  // namespace lidarshop

// Internal invariant; a failure is a bug in lidarshop, not in the input.
#define LIDARSHOP_CHECK(condition)                                                                    \
  do {                                                                                                \
    if (!(condition))                                                                                 \
      throw std::logic_error(fmt::format("{}:{}: check failed: {}", __FILE__, __LINE__, #condition)); \
  } while (false)
