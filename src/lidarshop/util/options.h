// One description per options struct: for each field its JSON key, kind, default, unit, one-line doc and valid
// range. Every front end is generated from it — the CLI flags and their help (cli/options_cli.h), JSON
// (ToJson / FromJson below), the HTTP API and the Python objects — so a field is documented and checked once.
//
// A module describes its structs in a `<module>/options_info.cc`:
//
//   template <>
//   const StructInfo& InfoOf<FillOptions>() {
//     static const StructInfo info = [] {
//       StructBuilder<FillOptions> b("FillOptions", "hole filling in scans");
//       b.Field(&FillOptions::patch_radius, "patch_radius", "patch half-width").Unit("cells").Range(1, 32);
//       b.Field(&FillOptions::method, "method", "fill method");  // an enum: its names come from EnumInfoOf
//       return b.Build();
//     }();
//     return info;
//   }
//
// and declares `template <> const StructInfo& InfoOf<FillOptions>();` next to the struct. Enums are described
// the same way by `EnumInfoOf<E>()` (util/enum_names.h), and convert to and from strings only through it.
//
// A result's part that only some runs have is a std::optional member (InpaintResult::review_stop, where a fill
// stopped for a review): ToJson leaves its key out when it holds nothing (FieldInfo::present), or writes null
// where the key has always been there (`.NullWhenAbsent()`). A list or string that is left out when empty says
// `.OmitWhenEmpty()`.
//
// A fixed-size matrix member (Eigen::Matrix4d world_from_scanner) is a JSON array of rows; a member of type
// nlohmann::ordered_json is free-form JSON (a job's result, whose type depends on the job).
//
// A result that has always been written flat although part of it is another described struct (`verify --json`:
// the report's keys beside VerifyResult's) says `b.Flatten(&VerifyReport::result)`: the held struct's fields are
// listed at the holder's level, each described once, where Flatten is called.
//
// A struct that holds another's options nests it (`InpaintOptions inpaint;` in FillOptions, described by
// `b.Field(&FillOptions::inpaint, ...)`) instead of copying its fields. Where fields used to be flat, the old
// keys stay as aliases (`b.Alias("patch_radius", "inpaint.patch_radius")`): JSON, the CLI's flags and Python's
// attributes accept them and set the nested field; ToJson writes only the nested form.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/util/enum_names.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// kNumberList: a std::vector of numbers (per-channel weights); the range applies to every element.
// kStringList: a std::vector<std::string> (a result's warnings, one sentence each).
// kStructList: a std::vector of a described struct (a resection's per-pair errors), a JSON array of objects.
// kNumberMatrix: a fixed-size matrix (Eigen::Matrix4d), a JSON array of rows; the range applies to every element.
// kJson: an nlohmann::ordered_json member, any JSON value.
enum class FieldKind {
  kBool,
  kInt,
  kUInt64,
  kDouble,
  kString,
  kEnum,
  kStruct,
  kNumberList,
  kStringList,
  kStructList,
  kNumberMatrix,
  kJson
};

template <class T>
struct IsVector : std::false_type {};
template <class T>
struct IsVector<std::vector<T>> : std::true_type {};
// A std::vector of a described struct (kStructList).
template <class T>
struct IsStructVector : std::false_type {};
template <class T>
struct IsStructVector<std::vector<T>>
    : std::bool_constant<std::is_class_v<T> && !std::is_same_v<T, std::string>> {};
template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};
// A fixed-size matrix (kNumberMatrix): Eigen's, or any type with RowsAtCompileTime, ColsAtCompileTime and
// operator()(row, column).
template <class T, class = void>
struct HasMatrixShape : std::false_type {};
template <class T>
struct HasMatrixShape<T, std::void_t<decltype(T::RowsAtCompileTime), decltype(T::ColsAtCompileTime)>>
    : std::true_type {};
template <class T>
inline constexpr bool kIsJsonValue =
    std::is_same_v<T, nlohmann::ordered_json> || std::is_same_v<T, nlohmann::json>;

struct StructInfo;

struct FieldInfo {
  std::string
      key;  // JSON key, snake_case; the CLI flag is --key with '-' for '_' unless a command renames it
  FieldKind kind = FieldKind::kInt;
  std::string doc;                 // one line, no trailing period
  std::string unit;                // "cells", "m", "deg", "px", "" for a pure number
  std::optional<double> min, max;  // valid range, inclusive unless the *_exclusive flag says otherwise
  bool min_exclusive = false, max_exclusive = false;
  int64_t integer_low = INT64_MIN,
          integer_high = INT64_MAX;      // kInt (and kNumberList of integers): type limits
  bool integer_elements = false;         // kNumberList of an integer type
  int matrix_rows = 0, matrix_cols = 0;  // kNumberMatrix
  const EnumInfo* choices = nullptr;     // kEnum
  const StructInfo* nested = nullptr;    // kStruct, kStructList: the (element's) description
  // Type-erased access to the field of a struct instance (`void*` = the struct described by the owner).
  std::function<nlohmann::ordered_json(const void*)> get;
  std::function<void(void*, const nlohmann::json&)> set;  // the value has passed CheckValue
  std::function<void*(void*)> nested_of;                  // kStruct: the member's address
  // kStructList: how many elements the member holds and the address of one (validation, Python). `set`
  // replaces the whole list from a JSON array, each element read with StructFromJson; its errors name the
  // element ("[2].rms_px: ...").
  std::function<size_t(const void*)> list_size;
  std::function<void*(void*, size_t)> element_of;
  // A std::optional member: whether it holds a value. ToJson leaves the key out when it does not (get then gives
  // the value a default T would have, which set or nested_of fill in); empty for every other field.
  std::function<bool(const void*)> present;
  // A std::optional member: empties it (JSON null where the field is NullWhenAbsent, None in Python).
  std::function<void(void*)> clear;
  bool null_when_absent = false;  // written as null, not left out, when absent (NullWhenAbsent)
  // An alias (StructInfo::aliases): the key path of the field it stands for ("inpaint.patch_radius"), and
  // how many fields of its struct were described before it (where its flag goes in the CLI's help). Its
  // get / set / nested_of reach that field from the alias's own struct.
  std::string alias_of;
  size_t position = 0;

  FieldInfo& Unit(std::string unit_name);
  FieldInfo& Range(double low, double high);
  FieldInfo& Min(double low);
  FieldInfo& Max(double high);
  FieldInfo& AboveZero();         // > 0
  FieldInfo& Below(double high);  // < high
  // A std::optional member whose key is always written: null when it holds nothing (and null on input empties
  // it). TypeScript `key: T | null`.
  FieldInfo& NullWhenAbsent();
  // A list, string or object left out of the JSON when empty (absent on input keeps it empty). TypeScript
  // `key?: T`.
  FieldInfo& OmitWhenEmpty();
  // "[1, 32]", "> 0", "[0, 1)" or "" when unbounded.
  std::string RangeText() const;
  // Throws OptionsError with a reason (no key) unless `value` is of this field's kind and inside its range.
  void CheckValue(const nlohmann::json& value) const;
  void CheckRange(double number, const std::string& text) const;
};

struct StructInfo {
  std::string name;  // the C++ struct, e.g. "FillOptions" (for documentation, never in user messages)
  std::string doc;
  std::vector<FieldInfo> fields;
  // Cross-field checks after every field is set (e.g. min < max); throws OptionsError. May be empty.
  std::function<void(const void*)> check;
  // Older keys of nested fields (FieldInfo::alias_of), accepted on input, never written. Not in `fields`:
  // everything that lists or writes a struct's fields sees each field once.
  std::vector<FieldInfo> aliases;
  // The JSON form of a default-constructed struct (ToJson(S{})): its own defaults, which a struct holding it
  // may change (FillOptions::inpaint starts from FillInpaintDefaults()).
  std::function<nlohmann::ordered_json()> default_json;
  const FieldInfo* Find(std::string_view key) const;       // a field (not an alias)
  const FieldInfo* FindAlias(std::string_view key) const;  // an alias
  std::vector<std::string> Keys() const;                   // the fields' keys, in order
  std::vector<std::string> AliasKeys() const;
};

// The field at `key_path` ("poisson.solver"; any segment may be an alias: "acceptance.enabled"), with the
// struct inside `object` its get / set apply to in *owner (an alias's own struct: its accessors reach the
// nested field) and the path without aliases in *canonical_path ("inpaint.acceptance.enabled"). nullptr when
// nothing has that path.
const FieldInfo* FindFieldPath(const StructInfo& info, const std::string& key_path, void* object,
                               void** owner, std::string* canonical_path);

// An alias `key` of the field at `target_path` inside `info` (StructBuilder::Alias).
FieldInfo MakeAlias(const StructInfo& info, std::string key, const std::string& target_path);

// An option with a bad value, found by key: `key_path` is the JSON path ("acceptance.band_px"), `reason` what
// is wrong ("0 is out of range [1, 64]"). what() is "key_path: reason"; the CLI words it with the flag instead.
class OptionsFieldError : public OptionsError {
 public:
  OptionsFieldError(std::string key_path, std::string reason);
  const std::string& key_path() const { return key_path_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string key_path_, reason_;
};

// The JSON form of `object` under `info`: every field, in declaration order; enums as their names.
nlohmann::ordered_json StructToJson(const StructInfo& info, const void* object);

// Sets the fields named in `json` (an object; absent keys keep their value in *object). Throws OptionsError
// naming the key path ("acceptance.band_px: 0 is out of range [1, 64]") for an unknown key (with the closest
// valid one), a wrong type or a value out of range; then runs the struct's cross-field check.
void StructFromJson(const StructInfo& info, const nlohmann::json& json, void* object,
                    const std::string& path = "");

// Checks every field of `object` against its description (kind, range), then the cross-field check; throws
// OptionsFieldError for the first bad field. Library entry points call it on the options they are given.
void ValidateStruct(const StructInfo& info, const void* object, const std::string& path = "");

template <class S>
void Validate(const S& object) {
  ValidateStruct(InfoOf<S>(), &object);
}

template <class S>
nlohmann::ordered_json ToJson(const S& object) {
  return StructToJson(InfoOf<S>(), &object);
}

// `base` with the fields of `json` applied (the defaults when `base` is not given).
template <class S>
S FromJson(const nlohmann::json& json, S base = S{}) {
  StructFromJson(InfoOf<S>(), json, &base);
  return base;
}

// Sets every field of `object` (recursively) to a valid value other than its current one where the
// description allows one, keeping the struct valid (a field whose change breaks a cross-field check keeps its
// value). For round-trip tests of every options struct, here and in the bindings. Returns the fields changed.
int SetSampleValues(const StructInfo& info, void* object);

// The value of one field as text for help and messages ("4", "0.2", "true", "patchmatch").
std::string ValueText(const nlohmann::ordered_json& value);

template <class S>
class StructBuilder {
 public:
  StructBuilder(std::string name, std::string doc) {
    info_.name = std::move(name);
    info_.doc = std::move(doc);
    info_.default_json = [] {
      const S defaults{};
      return StructToJson(InfoOf<S>(), &defaults);
    };
  }

  template <class T>
  FieldInfo& Field(T S::*member, std::string key, std::string doc) {
    FieldInfo& field = NewField(std::move(key), std::move(doc));
    Describe<T>(
        field, [member](const void* object) -> const T& { return static_cast<const S*>(object)->*member; },
        [member](void* object) -> T& { return static_cast<S*>(object)->*member; });
    return field;
  }

  // A member present in some results only: left out of the JSON when it holds nothing (or null, with
  // NullWhenAbsent). Reading or setting a nested part of an empty one gives it a value first.
  template <class T>
  FieldInfo& Field(std::optional<T> S::*member, std::string key, std::string doc) {
    FieldInfo& field = NewField(std::move(key), std::move(doc));
    Describe<T>(
        field,
        [member](const void* object) -> const T& {
          static const T empty = EmptyValue<T>();
          const std::optional<T>& value = static_cast<const S*>(object)->*member;
          return value ? *value : empty;
        },
        [member](void* object) -> T& {
          std::optional<T>& value = static_cast<S*>(object)->*member;
          if (!value) value.emplace(EmptyValue<T>());
          return *value;
        });
    field.present = [member](const void* object) {
      return (static_cast<const S*>(object)->*member).has_value();
    };
    field.clear = [member](void* object) { (static_cast<S*>(object)->*member).reset(); };
    return field;
  }

  // The fields of the described struct `member` listed here, at this struct's level (see the file comment).
  // Each keeps its description; its accessors reach into the member. The held struct's aliases and cross-field
  // check are not carried over. A key that is already a field here is a programming error.
  template <class T>
  void Flatten(T S::*member) {
    const auto inner = [member](const void* object) -> const void* {
      return &(static_cast<const S*>(object)->*member);
    };
    const auto inner_mutable = [member](void* object) -> void* {
      return &(static_cast<S*>(object)->*member);
    };
    for (FieldInfo field : InfoOf<T>().fields) {
      LIDARSHOP_CHECK(info_.Find(field.key) == nullptr && "a flattened key is a field already");
      field.get = [get = field.get, inner](const void* object) { return get(inner(object)); };
      if (field.set) {
        field.set = [set = field.set, inner_mutable](void* object, const nlohmann::json& json) {
          set(inner_mutable(object), json);
        };
      }
      if (field.nested_of) {
        field.nested_of = [nested_of = field.nested_of, inner_mutable](void* object) {
          return nested_of(inner_mutable(object));
        };
      }
      if (field.list_size) {
        field.list_size = [list_size = field.list_size, inner](const void* object) {
          return list_size(inner(object));
        };
      }
      if (field.element_of) {
        field.element_of = [element_of = field.element_of, inner_mutable](void* object, size_t index) {
          return element_of(inner_mutable(object), index);
        };
      }
      if (field.present) {
        field.present = [present = field.present, inner](const void* object) {
          return present(inner(object));
        };
      }
      if (field.clear) {
        field.clear = [clear = field.clear, inner_mutable](void* object) { clear(inner_mutable(object)); };
      }
      info_.fields.push_back(std::move(field));
    }
  }

  // `key` kept as an alias of the nested field at `target_path` ("patch_radius" for "inpaint.patch_radius"),
  // described after that struct's field. It has the target's kind, doc, unit and range; a narrower Range()
  // applies to the nested field inside this struct (FillOptions takes patches up to 15 cells, InpaintOptions
  // up to 64): checked with the cross-field checks, an error names the nested path ("inpaint.patch_radius").
  FieldInfo& Alias(std::string key, const std::string& target_path) {
    info_.aliases.push_back(MakeAlias(info_, std::move(key), target_path));
    return info_.aliases.back();
  }

  // Cross-field check of the whole struct, e.g. [](const S& s) { s.Check(); }.
  void Check(std::function<void(const S&)> check) {
    info_.check = [check = std::move(check)](const void* object) { check(*static_cast<const S*>(object)); };
  }

  StructInfo Build() { return std::move(info_); }

 private:
  FieldInfo& NewField(std::string key, std::string doc) {
    LIDARSHOP_CHECK(info_.Find(key) == nullptr && "a key is described twice");
    FieldInfo& field = info_.fields.emplace_back();
    field.key = std::move(key);
    field.doc = std::move(doc);
    return field;
  }

  // The value an empty optional reads as (a matrix of zeros: Eigen leaves a default one uninitialised).
  template <class T>
  static T EmptyValue() {
    if constexpr (HasMatrixShape<T>::value) {
      T matrix;
      for (int r = 0; r < T::RowsAtCompileTime; ++r)
        for (int c = 0; c < T::ColsAtCompileTime; ++c) matrix(r, c) = 0;
      return matrix;
    } else {
      return T{};
    }
  }

  // The kind, accessors and type limits of a member of type T, reached through `read` and `write`.
  template <class T, class Read, class Write>
  static void Describe(FieldInfo& field, Read read, Write write) {
    field.get = [read](const void* object) -> nlohmann::ordered_json { return ValueJson(read(object)); };
    if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      field.kind = FieldKind::kStringList;
      field.set = [write](void* object, const nlohmann::json& json) { write(object) = json.get<T>(); };
    } else if constexpr (kIsJsonValue<T>) {
      field.kind = FieldKind::kJson;
      field.set = [write](void* object, const nlohmann::json& json) { write(object) = json; };
    } else if constexpr (HasMatrixShape<T>::value) {
      static_assert(T::RowsAtCompileTime > 0 && T::ColsAtCompileTime > 0, "matrix fields have a fixed size");
      field.kind = FieldKind::kNumberMatrix;
      field.matrix_rows = T::RowsAtCompileTime;
      field.matrix_cols = T::ColsAtCompileTime;
      field.set = [write](void* object, const nlohmann::json& json) {
        T& matrix = write(object);
        for (int r = 0; r < T::RowsAtCompileTime; ++r)
          for (int c = 0; c < T::ColsAtCompileTime; ++c) matrix(r, c) = json[r][c].template get<double>();
      };
    } else if constexpr (IsStructVector<T>::value) {
      using Element = typename T::value_type;
      field.kind = FieldKind::kStructList;
      field.nested = &InfoOf<Element>();
      field.list_size = [read](const void* object) { return read(object).size(); };
      field.element_of = [write](void* object, size_t index) -> void* { return &write(object)[index]; };
      field.set = [write](void* object, const nlohmann::json& json) {
        T list(json.size());
        for (size_t i = 0; i < list.size(); ++i) {
          try {
            StructFromJson(InfoOf<Element>(), json[i], &list[i]);
          } catch (const OptionsFieldError& error) {
            throw OptionsFieldError("[" + std::to_string(i) + "]." + error.key_path(), error.reason());
          } catch (const OptionsError& error) {
            throw OptionsFieldError("[" + std::to_string(i) + "]", error.what());
          }
        }
        write(object) = std::move(list);
      };
    } else if constexpr (IsVector<T>::value) {
      using Element = typename T::value_type;
      static_assert(std::is_arithmetic_v<Element>, "list fields hold numbers, strings or described structs");
      field.kind = FieldKind::kNumberList;
      if constexpr (std::is_integral_v<Element>) {
        field.integer_elements = true;
        field.integer_low = std::numeric_limits<Element>::min();
        field.integer_high =
            static_cast<int64_t>(std::min<uint64_t>(std::numeric_limits<Element>::max(), INT64_MAX));
      }
      field.set = [write](void* object, const nlohmann::json& json) { write(object) = json.get<T>(); };
    } else if constexpr (std::is_class_v<T> && !std::is_same_v<T, std::string>) {
      field.kind = FieldKind::kStruct;
      field.nested = &InfoOf<T>();
      field.nested_of = [write](void* object) -> void* { return &write(object); };
    } else {
      field.kind = KindOf<T>();
      if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool> && !std::is_same_v<T, uint64_t>) {
        field.integer_low = std::numeric_limits<T>::min();
        field.integer_high = std::numeric_limits<T>::max();
      }
      if constexpr (std::is_enum_v<T>) field.choices = &EnumInfoOf<T>();
      field.set = [write](void* object, const nlohmann::json& json) {
        if constexpr (std::is_enum_v<T>) {
          write(object) = ParseEnum<T>(json.get<std::string>());
        } else {
          write(object) = json.get<T>();
        }
      };
    }
  }

  // The JSON form of one member's value.
  template <class T>
  static nlohmann::ordered_json ValueJson(const T& value) {
    if constexpr (std::is_enum_v<T>) {
      return std::string(ToString(value));
    } else if constexpr (std::is_floating_point_v<T>) {
      // NaN ("none", e.g. a consistency with nothing to compare) is JSON null.
      return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
    } else if constexpr (kIsJsonValue<T>) {
      return nlohmann::ordered_json(value);
    } else if constexpr (HasMatrixShape<T>::value) {
      nlohmann::ordered_json rows = nlohmann::ordered_json::array();
      for (int r = 0; r < T::RowsAtCompileTime; ++r) {
        nlohmann::ordered_json row = nlohmann::ordered_json::array();
        for (int c = 0; c < T::ColsAtCompileTime; ++c) row.push_back(ValueJson(double(value(r, c))));
        rows.push_back(std::move(row));
      }
      return rows;
    } else if constexpr (IsStructVector<T>::value) {
      nlohmann::ordered_json list = nlohmann::ordered_json::array();
      for (const auto& element : value)
        list.push_back(StructToJson(InfoOf<typename T::value_type>(), &element));
      return list;
    } else if constexpr (IsVector<T>::value) {
      return nlohmann::ordered_json(value);
    } else if constexpr (std::is_class_v<T> && !std::is_same_v<T, std::string>) {
      return StructToJson(InfoOf<T>(), &value);
    } else {
      return value;
    }
  }

  template <class T>
  static constexpr FieldKind KindOf() {
    if constexpr (std::is_same_v<T, bool>) {
      return FieldKind::kBool;
    } else if constexpr (std::is_enum_v<T>) {
      return FieldKind::kEnum;
    } else if constexpr (std::is_same_v<T, uint64_t>) {
      return FieldKind::kUInt64;
    } else if constexpr (std::is_integral_v<T>) {
      static_assert(sizeof(T) <= sizeof(int64_t), "integer fields are at most 64-bit");
      return FieldKind::kInt;
    } else if constexpr (std::is_floating_point_v<T>) {
      return FieldKind::kDouble;
    } else {
      static_assert(std::is_same_v<T, std::string>,
                    "a field is bool, a number, an enum, a string or a struct");
      return FieldKind::kString;
    }
  }

  StructInfo info_;
};

}  // namespace lidarshop
