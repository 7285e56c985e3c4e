// A cursor over an in-memory text buffer for the hand-rolled ASCII readers (PTX,
// PLY ascii, OBJ, MTL, PCD ascii).
//
// Numbers are parsed with std::from_chars (locale independent, no allocation), which is what lets the PTX
// reader run at hundreds of MB/s. The cursor counts lines so that every error names "file: line N: field 'f':
// ...". Lines may end in "\n" or "\r\n".
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop::io_internal {

// At most `max_chars` characters of `text` (40: for error messages), with bytes that are not printable ASCII
// shown as '?'.
inline std::string Printable(std::string_view text, size_t max_chars = 40) {
  std::string out(text.substr(0, max_chars));
  for (char& c : out) {
    if (c < 32 || c > 126) c = '?';
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

class TextCursor {
 public:
  TextCursor(std::string_view text, std::string file, int64_t first_line = 1)
      : begin_(text.data()),
        p_(text.data()),
        end_(text.data() + text.size()),
        file_(std::move(file)),
        line_(first_line) {}

  bool AtEnd() const { return p_ >= end_; }
  int64_t line() const { return line_; }
  int64_t offset() const { return p_ - begin_; }
  int64_t remaining() const { return end_ - p_; }
  const std::string& file() const { return file_; }
  const char* position() const { return p_; }

  // Skips spaces, tabs and '\r' (not newlines).
  void SkipBlanks() {
    while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r')) ++p_;
  }
  // True at '\n' or at the end of the buffer (after blanks).
  bool AtEndOfLine() {
    SkipBlanks();
    return p_ >= end_ || *p_ == '\n';
  }
  // Moves past the next '\n' (or to the end).
  void NextLine() {
    while (p_ < end_ && *p_ != '\n') ++p_;
    if (p_ < end_) {
      ++p_;
      ++line_;
    }
  }
  // Skips lines holding only blanks.
  void SkipEmptyLines() {
    for (;;) {
      const char* q = p_;
      while (q < end_ && (*q == ' ' || *q == '\t' || *q == '\r')) ++q;
      if (q < end_ && *q == '\n') {
        p_ = q + 1;
        ++line_;
      } else {
        p_ = q;
        return;
      }
    }
  }
  // The next blank-delimited token on the current line; empty at the end of the line.
  std::string_view Token() {
    SkipBlanks();
    const char* start = p_;
    while (p_ < end_ && !IsSpace(*p_)) ++p_;
    return std::string_view(start, p_ - start);
  }
  // The rest of the current line without the line ending (the cursor stays on the line ending).
  std::string_view RestOfLine() {
    SkipBlanks();
    const char* start = p_;
    while (p_ < end_ && *p_ != '\n') ++p_;
    const char* stop = p_;
    while (stop > start && (stop[-1] == '\r' || stop[-1] == ' ' || stop[-1] == '\t')) --stop;
    return std::string_view(start, stop - start);
  }

  // Parses the next token as a finite number; throws InputError naming `field` otherwise.
  // `allow_nonfinite` accepts "nan" and "inf" (PCD marks missing points so).
  template <typename T>
  T Number(std::string_view field, bool allow_nonfinite = false) {
    SkipBlanks();
    if (p_ >= end_ || *p_ == '\n') Fail(field, "missing (the line ends too early)");
    const char* start = p_;
    if (*start == '+') ++start;
    T value{};
    const auto [stop, error] = std::from_chars(start, end_, value);
    if (error != std::errc() || (stop < end_ && !IsSpace(*stop) && !IsSeparator(*stop))) {
      const char* token_end = p_;
      while (token_end < end_ && !IsSpace(*token_end) && !IsSeparator(*token_end)) ++token_end;
      const std::string token = Printable(std::string_view(p_, token_end - p_));
      if (error == std::errc::result_out_of_range)
        Fail(field, fmt::format("number out of range: '{}'", token));
      Fail(field, fmt::format("not a number: '{}'", token));
    }
    if constexpr (std::is_floating_point_v<T>) {
      if (!allow_nonfinite && !std::isfinite(value)) {
        Fail(field, fmt::format("not a finite number: '{}'", Printable(std::string_view(p_, stop - p_))));
      }
    }
    p_ = stop;
    if (separator_ != 0) {
      SkipBlanks();
      if (p_ < end_ && *p_ == separator_) ++p_;
    }
    return value;
  }
  double Double(std::string_view field) { return Number<double>(field); }
  float Float(std::string_view field) { return Number<float>(field); }
  int64_t Int(std::string_view field) { return Number<int64_t>(field); }

  // Throws unless only blanks remain on the line; then moves to the next line.
  void EndLine(std::string_view what) {
    if (!AtEndOfLine()) {
      const std::string_view extra = Token();
      Fail("", fmt::format("unexpected extra token '{}' after {}", Printable(extra), what));
    }
    NextLine();
  }

  [[noreturn]] void Fail(std::string_view field, std::string_view message) const {
    ThrowInputError(file_, fmt::format("line {}", line_), field, message);
  }

  static bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

  // Also accept `separator` (e.g. ',') after a number, before blanks or the next number (PCD ascii data as
  // PDAL writes it); 0 = numbers are separated by blanks only.
  void set_separator(char separator) { separator_ = separator; }

 private:
  const char* begin_;
  const char* p_;
  const char* end_;
  std::string file_;
  int64_t line_;
  char separator_ = 0;

  bool IsSeparator(char c) const { return separator_ != 0 && c == separator_; }
};

}  // namespace lidarshop::io_internal
