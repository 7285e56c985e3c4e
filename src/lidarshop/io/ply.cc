#include "lidarshop/io/ply.h"

#include <bit>
#include <cstring>

#include <fmt/format.h>

#include "lidarshop/io/io_common.h"
#include "lidarshop/io/text_cursor.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"

namespace lidarshop {
namespace {

using io_internal::TextCursor;

struct TypeInfo {
  const char* name;
  const char* alias;
  PlyType type;
  int size;
};
constexpr TypeInfo kTypes[] = {
    {"char", "int8", PlyType::kInt8, 1},        {"uchar", "uint8", PlyType::kUInt8, 1},
    {"short", "int16", PlyType::kInt16, 2},     {"ushort", "uint16", PlyType::kUInt16, 2},
    {"int", "int32", PlyType::kInt32, 4},       {"uint", "uint32", PlyType::kUInt32, 4},
    {"float", "float32", PlyType::kFloat32, 4}, {"double", "float64", PlyType::kFloat64, 8},
};

int SizeOf(PlyType type) { return kTypes[static_cast<int>(type)].size; }
const char* NameOf(PlyType type) { return kTypes[static_cast<int>(type)].name; }
bool IsInteger(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

bool ParseType(std::string_view token, PlyType* type) {
  for (const TypeInfo& info : kTypes) {
    if (token == info.name || token == info.alias) {
      *type = info.type;
      return true;
    }
  }
  return false;
}

template <typename T>
T Load(const char* p, bool swap) {
  T value;
  if (swap) {
    char bytes[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) bytes[i] = p[sizeof(T) - 1 - i];
    std::memcpy(&value, bytes, sizeof(T));
  } else {
    std::memcpy(&value, p, sizeof(T));
  }
  return value;
}

double LoadValue(const char* p, PlyType type, bool swap) {
  switch (type) {
    case PlyType::kInt8:
      return static_cast<int8_t>(*p);
    case PlyType::kUInt8:
      return static_cast<uint8_t>(*p);
    case PlyType::kInt16:
      return Load<int16_t>(p, swap);
    case PlyType::kUInt16:
      return Load<uint16_t>(p, swap);
    case PlyType::kInt32:
      return Load<int32_t>(p, swap);
    case PlyType::kUInt32:
      return Load<uint32_t>(p, swap);
    case PlyType::kFloat32:
      return Load<float>(p, swap);
    case PlyType::kFloat64:
      return Load<double>(p, swap);
  }
  return 0;
}

// Smallest bytes (binary) or characters (ASCII) one record of `element` can take.
int64_t MinimumRecordSize(const PlyElement& element, bool ascii) {
  int64_t size = 0;
  for (const PlyProperty& property : element.properties) {
    size += ascii ? 2 : SizeOf(property.is_list ? property.count_type : property.type);
  }
  return std::max<int64_t>(size, 1);
}

// A PLY header: "ply", "format ...", then element/property/comment lines up to "end_header".
PlyData ParseHeader(const std::string& bytes, const std::string& file, size_t* data_offset,
                    int64_t* data_line) {
  const size_t header_end = bytes.find("end_header");
  if (bytes.compare(0, 3, "ply") != 0) {
    ThrowInputError(file, "line 1", "magic", "not a PLY file (it does not start with 'ply')");
  }
  if (header_end == std::string::npos) {
    ThrowInputError(file, "header", "end_header", "missing: the header never ends (truncated file?)");
  }
  size_t after = bytes.find('\n', header_end);
  after = after == std::string::npos ? bytes.size() : after + 1;
  TextCursor cursor(std::string_view(bytes.data(), after), file);
  PlyData data;
  bool have_format = false;
  cursor.NextLine();
  for (;;) {
    cursor.SkipEmptyLines();
    if (cursor.AtEnd()) cursor.Fail("end_header", "missing");
    const std::string_view keyword = cursor.Token();
    if (keyword == "end_header") {
      cursor.NextLine();
      break;
    }
    if (keyword == "format") {
      const std::string_view format = cursor.Token();
      if (format == "ascii") {
        data.format = PlyData::Format::kAscii;
      } else if (format == "binary_little_endian") {
        data.format = PlyData::Format::kBinaryLittleEndian;
      } else if (format == "binary_big_endian") {
        data.format = PlyData::Format::kBinaryBigEndian;
      } else {
        cursor.Fail("format", fmt::format("unknown format '{}'", io_internal::Printable(format)));
      }
      cursor.Token();  // version
      have_format = true;
    } else if (keyword == "comment" || keyword == "obj_info") {
      if (keyword == "comment") data.comments.emplace_back(cursor.RestOfLine());
    } else if (keyword == "element") {
      PlyElement element;
      element.name = std::string(cursor.Token());
      element.count = cursor.Int("element count");
      if (element.count < 0) cursor.Fail("element count", "negative");
      data.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (data.elements.empty()) cursor.Fail("property", "a property before any element");
      PlyProperty property;
      std::string_view type = cursor.Token();
      if (type == "list") {
        property.is_list = true;
        const std::string_view count_type = cursor.Token();
        if (!ParseType(count_type, &property.count_type) || !IsInteger(property.count_type)) {
          cursor.Fail("property",
                      fmt::format("bad list count type '{}'", io_internal::Printable(count_type)));
        }
        type = cursor.Token();
      }
      if (!ParseType(type, &property.type)) {
        cursor.Fail("property", fmt::format("unknown type '{}'", io_internal::Printable(type)));
      }
      property.name = std::string(cursor.Token());
      if (property.name.empty()) cursor.Fail("property", "missing name");
      data.elements.back().properties.push_back(std::move(property));
    } else {
      cursor.Fail("header", fmt::format("unknown keyword '{}'", io_internal::Printable(keyword)));
    }
    cursor.NextLine();
  }
  if (!have_format) ThrowInputError(file, "header", "format", "missing");
  *data_offset = after;
  *data_line = cursor.line();
  return data;
}

void ReadAscii(const std::string& bytes, const std::string& file, size_t offset, int64_t line,
               PlyData* data) {
  TextCursor cursor(std::string_view(bytes).substr(offset), file, line);
  for (PlyElement& element : data->elements) {
    for (PlyProperty& property : element.properties) {
      if (property.is_list) {
        property.offsets.reserve(element.count + 1);
        property.offsets.push_back(0);
      } else {
        property.values.reserve(element.count);
      }
    }
    for (int64_t record = 0; record < element.count; ++record) {
      cursor.SkipEmptyLines();
      if (cursor.AtEnd()) {
        cursor.Fail(element.name,
                    fmt::format("truncated: the header claims {} records, found {}", element.count, record));
      }
      for (PlyProperty& property : element.properties) {
        if (property.is_list) {
          const int64_t count = cursor.Int(property.name + " (list size)");
          if (count < 0 || count > 1 << 20)
            cursor.Fail(property.name, fmt::format("bad list size {}", count));
          for (int64_t i = 0; i < count; ++i) property.values.push_back(cursor.Double(property.name));
          property.offsets.push_back(static_cast<int64_t>(property.values.size()));
        } else {
          property.values.push_back(cursor.Double(property.name));
        }
      }
      cursor.EndLine(fmt::format("the properties of {} {}", element.name, record));
    }
  }
  cursor.SkipEmptyLines();
  if (!cursor.AtEnd()) {
    cursor.Fail("element counts", "more data follows the records the header declares (wrong count?)");
  }
}

void ReadBinary(const std::string& bytes, const std::string& file, size_t offset, bool swap, PlyData* data) {
  const char* p = bytes.data() + offset;
  const char* end = bytes.data() + bytes.size();
  auto fail = [&](const std::string& field, const std::string& message) {
    ThrowInputError(file, fmt::format("byte {}", p - bytes.data()), field, message);
  };
  for (PlyElement& element : data->elements) {
    int64_t record_size = 0;
    bool fixed = true;
    for (PlyProperty& property : element.properties) {
      fixed = fixed && !property.is_list;
      record_size += SizeOf(property.type);
      if (property.is_list) {
        property.offsets.reserve(element.count + 1);
        property.offsets.push_back(0);
      } else {
        property.values.reserve(element.count);
      }
    }
    for (int64_t record = 0; record < element.count; ++record) {
      if (fixed && end - p < record_size) {
        fail(element.name, fmt::format("truncated: the header claims {} records, the file ends in record {}",
                                       element.count, record));
      }
      for (PlyProperty& property : element.properties) {
        if (property.is_list) {
          const int count_size = SizeOf(property.count_type);
          if (end - p < count_size)
            fail(property.name, fmt::format("truncated in {} {}", element.name, record));
          const double count = LoadValue(p, property.count_type, swap);
          if (count < 0 || count > (1 << 20)) fail(property.name, fmt::format("bad list size {}", count));
          p += count_size;
          const int size = SizeOf(property.type);
          if (end - p < count * size)
            fail(property.name, fmt::format("truncated in {} {}", element.name, record));
          for (int i = 0; i < static_cast<int>(count); ++i, p += size) {
            property.values.push_back(LoadValue(p, property.type, swap));
          }
          property.offsets.push_back(static_cast<int64_t>(property.values.size()));
        } else {
          if (end - p < SizeOf(property.type)) {
            fail(property.name, fmt::format("truncated in {} {}", element.name, record));
          }
          const double value = LoadValue(p, property.type, swap);
          if (!std::isfinite(value))
            fail(property.name, fmt::format("not a finite number in {} {}", element.name, record));
          property.values.push_back(value);
          p += SizeOf(property.type);
        }
      }
    }
  }
  // A writer may end the file with a line break; anything more means the counts disagree with the data.
  if (end - p > 1) {
    ThrowInputError(file, fmt::format("byte {}", p - bytes.data()), "element counts",
                    fmt::format("{} bytes follow the records the header declares (wrong count?)", end - p));
  }
}

void AppendBinary(std::string* out, double value, PlyType type) {
  char buffer[8];
  auto put = [&](auto typed) {
    std::memcpy(buffer, &typed, sizeof(typed));
    out->append(buffer, sizeof(typed));
  };
  switch (type) {
    case PlyType::kInt8:
      put(static_cast<int8_t>(value));
      break;
    case PlyType::kUInt8:
      put(static_cast<uint8_t>(value));
      break;
    case PlyType::kInt16:
      put(static_cast<int16_t>(value));
      break;
    case PlyType::kUInt16:
      put(static_cast<uint16_t>(value));
      break;
    case PlyType::kInt32:
      put(static_cast<int32_t>(value));
      break;
    case PlyType::kUInt32:
      put(static_cast<uint32_t>(value));
      break;
    case PlyType::kFloat32:
      put(static_cast<float>(value));
      break;
    case PlyType::kFloat64:
      put(value);
      break;
  }
}

void AppendAscii(std::string* out, double value, PlyType type) {
  if (IsInteger(type)) {
    io_internal::AppendNumber(out, static_cast<int64_t>(value));
  } else if (type == PlyType::kFloat32) {
    io_internal::AppendNumber(out, static_cast<float>(value));
  } else {
    io_internal::AppendNumber(out, value);
  }
}

}  // namespace

const PlyProperty* PlyElement::Find(const std::string& name) const {
  for (const PlyProperty& property : properties) {
    if (property.name == name) return &property;
  }
  return nullptr;
}

const PlyElement* PlyData::Find(const std::string& name) const {
  for (const PlyElement& element : elements) {
    if (element.name == name) return &element;
  }
  return nullptr;
}

PlyData ParsePly(const std::string& bytes, const std::string& file) {
  if (bytes.empty()) ThrowInputError(file, "byte 0", "magic", "the file is empty");
  size_t offset = 0;
  int64_t line = 1;
  PlyData data = ParseHeader(bytes, file, &offset, &line);
  const bool ascii = data.format == PlyData::Format::kAscii;
  // Refuse counts the rest of the file cannot hold, before allocating anything.
  const int64_t available = static_cast<int64_t>(bytes.size() - offset);
  int64_t needed = 0;
  for (const PlyElement& element : data.elements) {
    const int64_t record = MinimumRecordSize(element, ascii);
    if (element.count > available / record + 1 || needed > available) {
      ThrowInputError(
          file, "header", fmt::format("element {}", element.name),
          fmt::format("claims {} records but only {} bytes of data follow", element.count, available));
    }
    needed += element.count * record;
  }
  if (needed > available + 1) {
    ThrowInputError(file, "header", "element counts",
                    fmt::format("the elements need at least {} bytes but only {} follow (truncated file?)",
                                needed, available));
  }
  if (ascii) {
    ReadAscii(bytes, file, offset, line, &data);
  } else {
    const bool big = data.format == PlyData::Format::kBinaryBigEndian;
    ReadBinary(bytes, file, offset, big != (std::endian::native == std::endian::big), &data);
  }
  return data;
}

PlyData ReadPly(const std::string& path) { return ParsePly(io_internal::ReadFileToString(path), path); }

PlyData ReadPlyHeader(const std::string& path, int64_t* data_bytes) {
  constexpr int64_t kMaxHeaderBytes = 1 << 20;
  const int64_t file_bytes = CheckRegularFile(path);
  const std::string prefix = io_internal::ReadFilePrefix(path, kMaxHeaderBytes);
  if (prefix.compare(0, 3, "ply") == 0 && prefix.find("end_header") == std::string::npos &&
      file_bytes > kMaxHeaderBytes) {
    ThrowInputError(path, "header", "end_header",
                    fmt::format("missing in the first {} bytes: not a PLY header", kMaxHeaderBytes));
  }
  size_t data_offset = 0;
  int64_t data_line = 0;
  PlyData data = ParseHeader(prefix, path, &data_offset, &data_line);
  if (data_bytes != nullptr) *data_bytes = file_bytes - static_cast<int64_t>(data_offset);
  return data;
}

void WritePly(const std::string& path, const PlyData& data) {
  const bool ascii = data.format == PlyData::Format::kAscii;
  std::string out = fmt::format("ply\nformat {} 1.0\n", ascii ? "ascii" : "binary_little_endian");
  for (const std::string& comment : data.comments) out += "comment " + comment + "\n";
  for (const PlyElement& element : data.elements) {
    out += fmt::format("element {} {}\n", element.name, element.count);
    for (const PlyProperty& property : element.properties) {
      const size_t expected = property.is_list ? element.count + 1 : element.count;
      const size_t size = property.is_list ? property.offsets.size() : property.values.size();
      LIDARSHOP_CHECK(size == expected);
      if (property.is_list) {
        out += fmt::format("property list {} {} {}\n", NameOf(property.count_type), NameOf(property.type),
                           property.name);
      } else {
        out += fmt::format("property {} {}\n", NameOf(property.type), property.name);
      }
    }
  }
  out += "end_header\n";
  for (const PlyElement& element : data.elements) {
    for (int64_t record = 0; record < element.count; ++record) {
      bool first = true;
      for (const PlyProperty& property : element.properties) {
        if (ascii && !first) out += ' ';
        first = false;
        if (property.is_list) {
          const int64_t begin = property.offsets[record], end = property.offsets[record + 1];
          if (ascii) {
            io_internal::AppendNumber(&out, end - begin);
          } else {
            AppendBinary(&out, static_cast<double>(end - begin), property.count_type);
          }
          for (int64_t i = begin; i < end; ++i) {
            if (ascii) {
              out += ' ';
              AppendAscii(&out, property.values[i], property.type);
            } else {
              AppendBinary(&out, property.values[i], property.type);
            }
          }
        } else if (ascii) {
          AppendAscii(&out, property.values[record], property.type);
        } else {
          AppendBinary(&out, property.values[record], property.type);
        }
      }
      if (ascii) out += '\n';
    }
  }
  WriteFileAtomically(path, [&](std::ostream& stream) { stream.write(out.data(), out.size()); });
}

}  // namespace lidarshop
