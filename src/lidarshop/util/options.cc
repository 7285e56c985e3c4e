#include "lidarshop/util/options.h"

#include "lidarshop/util/simd.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace lidarshop {

// ---- enums ----

const std::string& EnumInfo::Name(int value) const {
  for (const Choice& choice : choices) {
    if (choice.value == value) return choice.name;
  }
  LIDARSHOP_CHECK(!"enum value without a name");
  return choices.front().name;
}

std::string EnumInfo::NamesText(std::string_view separator) const {
  std::string text;
  for (const Choice& choice : choices) {
    if (!text.empty()) text += separator;
    text += choice.name;
  }
  return text;
}

int EnumInfo::Parse(std::string_view name) const {
  std::vector<std::string> names;
  for (const Choice& choice : choices) {
    if (choice.name == name) return choice.value;
    names.push_back(choice.name);
  }
  const std::string closest = ClosestMatch(name, names);
  throw OptionsError(fmt::format("'{}' is not a {}: {}{}", name, doc, NamesText(),
                                 closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest)));
}

namespace {

size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
    }
  }
  return row[b.size()];
}

}  // namespace

std::string ClosestMatch(std::string_view text, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = std::max<size_t>(1, text.size() / 2) + 1;
  for (const std::string& candidate : candidates) {
    const size_t distance = EditDistance(text, candidate);
    // A prefix ("--patch" for "--patch-radius") is as good as a typo.
    const bool prefix = text.size() >= 3 && candidate.compare(0, text.size(), text) == 0;
    const size_t score = prefix ? std::min<size_t>(distance, 1) : distance;
    if (score < best_distance) {
      best_distance = score;
      best = candidate;
    }
  }
  return best;
}

// ---- fields ----

FieldInfo& FieldInfo::Unit(std::string unit_name) {
  unit = std::move(unit_name);
  return *this;
}

FieldInfo& FieldInfo::Range(double low, double high) {
  min = low;
  max = high;
  return *this;
}

FieldInfo& FieldInfo::Min(double low) {
  min = low;
  return *this;
}

FieldInfo& FieldInfo::Max(double high) {
  max = high;
  return *this;
}

FieldInfo& FieldInfo::AboveZero() {
  min = 0;
  min_exclusive = true;
  return *this;
}

FieldInfo& FieldInfo::Below(double high) {
  max = high;
  max_exclusive = true;
  return *this;
}

FieldInfo& FieldInfo::NullWhenAbsent() {
  LIDARSHOP_CHECK(clear && "NullWhenAbsent is for std::optional members");
  null_when_absent = true;
  return *this;
}

FieldInfo& FieldInfo::OmitWhenEmpty() {
  LIDARSHOP_CHECK(!present && (kind == FieldKind::kString || kind == FieldKind::kNumberList ||
                               kind == FieldKind::kStringList || kind == FieldKind::kStructList ||
                               kind == FieldKind::kJson));
  present = [get = get](const void* object) {
    const nlohmann::ordered_json value = get(object);
    // nlohmann's empty() is false for every string: a string is a value, not a container.
    if (value.is_string()) return !value.get_ref<const std::string&>().empty();
    return !(value.is_null() || ((value.is_array() || value.is_object()) && value.empty()));
  };
  return *this;
}

std::string FieldInfo::RangeText() const {
  if (min && max) {
    return fmt::format("{}{}, {}{}", min_exclusive ? "(" : "[", *min, *max, max_exclusive ? ")" : "]");
  }
  if (min) return fmt::format("{} {}", min_exclusive ? ">" : ">=", *min);
  if (max) return fmt::format("{} {}", max_exclusive ? "<" : "<=", *max);
  return "";
}

void FieldInfo::CheckValue(const nlohmann::json& value) const {
  switch (kind) {
    case FieldKind::kBool:
      if (!value.is_boolean())
        throw OptionsError(fmt::format("expected true or false, got {}", value.dump()));
      return;
    case FieldKind::kString:
      if (!value.is_string()) throw OptionsError(fmt::format("expected a string, got {}", value.dump()));
      return;
    case FieldKind::kEnum:
      if (!value.is_string()) {
        throw OptionsError(fmt::format("expected one of {}, got {}", choices->NamesText(), value.dump()));
      }
      choices->Parse(value.get<std::string>());
      return;
    case FieldKind::kStruct:
      if (!value.is_object()) throw OptionsError(fmt::format("expected an object, got {}", value.dump()));
      return;
    case FieldKind::kStructList:
      if (!value.is_array() ||
          std::any_of(value.begin(), value.end(), [](const auto& element) { return !element.is_object(); })) {
        throw OptionsError(fmt::format("expected a list of objects, got {}", value.dump()));
      }
      return;
    case FieldKind::kNumberList:
      if (!value.is_array())
        throw OptionsError(fmt::format("expected a list of numbers, got {}", value.dump()));
      for (const auto& element : value) {
        if (!element.is_number() || !std::isfinite(element.get<double>())) {
          throw OptionsError(fmt::format("expected a list of numbers, got {}", value.dump()));
        }
        if (integer_elements && (!element.is_number_integer() || element.get<double>() < integer_low ||
                                 element.get<double>() > integer_high)) {
          throw OptionsError(fmt::format("expected a list of whole numbers, got {}", value.dump()));
        }
        CheckRange(element.get<double>(), element.dump());
      }
      return;
    case FieldKind::kStringList:
      if (!value.is_array() ||
          std::any_of(value.begin(), value.end(), [](const auto& element) { return !element.is_string(); })) {
        throw OptionsError(fmt::format("expected a list of strings, got {}", value.dump()));
      }
      return;
    case FieldKind::kNumberMatrix: {
      const auto is_row = [this](const nlohmann::json& row) {
        return row.is_array() && row.size() == size_t(matrix_cols) &&
               std::all_of(row.begin(), row.end(), [](const nlohmann::json& element) {
                 return element.is_number() && std::isfinite(element.get<double>());
               });
      };
      if (!value.is_array() || value.size() != size_t(matrix_rows) ||
          !std::all_of(value.begin(), value.end(), is_row)) {
        throw OptionsError(
            fmt::format("expected {} rows of {} numbers, got {}", matrix_rows, matrix_cols, value.dump()));
      }
      for (const auto& row : value)
        for (const auto& element : row) CheckRange(element.get<double>(), element.dump());
      return;
    }
    case FieldKind::kJson:
      return;
    case FieldKind::kUInt64:
      if (!value.is_number_unsigned() && !(value.is_number_integer() && value.get<int64_t>() >= 0)) {
        throw OptionsError(fmt::format("expected a whole number >= 0, got {}", value.dump()));
      }
      break;
    case FieldKind::kInt: {
      if (!value.is_number_integer()) {
        throw OptionsError(fmt::format("expected a whole number, got {}", value.dump()));
      }
      const bool too_large = value.is_number_unsigned() && value.get<uint64_t>() > uint64_t(INT64_MAX);
      if (too_large || value.get<int64_t>() < integer_low || value.get<int64_t>() > integer_high) {
        throw OptionsError(fmt::format("{} does not fit the field's integer type", value.dump()));
      }
      break;
    }
    case FieldKind::kDouble:
      if (!value.is_number()) throw OptionsError(fmt::format("expected a number, got {}", value.dump()));
      if (!std::isfinite(value.get<double>())) throw OptionsError("expected a finite number");
      break;
  }
  CheckRange(value.get<double>(), value.dump());
}

void FieldInfo::CheckRange(double number, const std::string& text) const {
  const bool low = min && (min_exclusive ? number <= *min : number < *min);
  const bool high = max && (max_exclusive ? number >= *max : number > *max);
  if (low || high) throw OptionsError(fmt::format("{} is out of range {}", text, RangeText()));
}

// ---- structs ----

OptionsFieldError::OptionsFieldError(std::string key_path, std::string reason)
    : OptionsError(key_path + ": " + reason), key_path_(std::move(key_path)), reason_(std::move(reason)) {}

namespace {

std::string Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

// Cross-field checks throw OptionsError (no key) or OptionsFieldError (a key inside the struct). An alias's
// narrower range is one: the nested field is checked against it, under its own path.
void RunCheck(const StructInfo& info, const void* object, const std::string& path) {
  for (const FieldInfo& alias : info.aliases) {
    if (alias.kind == FieldKind::kStruct) continue;
    try {
      alias.CheckValue(alias.get(object));
    } catch (const OptionsError& error) {
      throw OptionsFieldError(Join(path, alias.alias_of), error.what());
    }
  }
  if (!info.check) return;
  try {
    info.check(object);
  } catch (const OptionsFieldError& error) {
    throw OptionsFieldError(Join(path, error.key_path()), error.reason());
  } catch (const OptionsError& error) {
    if (path.empty()) throw;
    throw OptionsFieldError(path, error.what());
  }
}

}  // namespace

void ValidateStruct(const StructInfo& info, const void* object, const std::string& path) {
  for (const FieldInfo& field : info.fields) {
    if (field.present && !field.present(object)) continue;
    if (field.kind == FieldKind::kStruct) {
      ValidateStruct(*field.nested, field.nested_of(const_cast<void*>(object)), Join(path, field.key));
      continue;
    }
    if (field.kind == FieldKind::kStructList) {
      for (size_t i = 0; i < field.list_size(object); ++i) {
        ValidateStruct(*field.nested, field.element_of(const_cast<void*>(object), i),
                       fmt::format("{}[{}]", Join(path, field.key), i));
      }
      continue;
    }
    try {
      field.CheckValue(field.get(object));
    } catch (const OptionsError& error) {
      throw OptionsFieldError(Join(path, field.key), error.what());
    }
  }
  RunCheck(info, object, path);
}

const FieldInfo* StructInfo::Find(std::string_view key) const {
  for (const FieldInfo& field : fields) {
    if (field.key == key) return &field;
  }
  return nullptr;
}

const FieldInfo* StructInfo::FindAlias(std::string_view key) const {
  for (const FieldInfo& alias : aliases) {
    if (alias.key == key) return &alias;
  }
  return nullptr;
}

std::vector<std::string> StructInfo::Keys() const {
  std::vector<std::string> keys;
  for (const FieldInfo& field : fields) keys.push_back(field.key);
  return keys;
}

std::vector<std::string> StructInfo::AliasKeys() const {
  std::vector<std::string> keys;
  for (const FieldInfo& alias : aliases) keys.push_back(alias.key);
  return keys;
}

FieldInfo MakeAlias(const StructInfo& info, std::string key, const std::string& target_path) {
  // The target's struct from the alias's: the nested_of of each struct on the way, composed. Copies of the
  // accessors, not pointers: `info` is still being built and its fields may move.
  std::function<void*(void*)> owner_of = [](void* object) { return object; };
  const StructInfo* current = &info;
  const FieldInfo* field = nullptr;
  for (size_t start = 0;;) {
    const size_t dot = target_path.find('.', start);
    field = current->Find(target_path.substr(start, dot == std::string::npos ? dot : dot - start));
    LIDARSHOP_CHECK(field != nullptr && "an alias names a described field");
    if (dot == std::string::npos) break;
    LIDARSHOP_CHECK(field->kind == FieldKind::kStruct);
    owner_of = [owner_of, nested_of = field->nested_of](void* object) { return nested_of(owner_of(object)); };
    current = field->nested;
    start = dot + 1;
  }
  LIDARSHOP_CHECK(info.Find(key) == nullptr && info.FindAlias(key) == nullptr);
  FieldInfo alias = *field;  // kind, doc, unit, range, choices, nested struct
  alias.key = std::move(key);
  alias.alias_of = target_path;
  alias.position = info.fields.size();
  alias.get = [get = field->get, owner_of](const void* object) {
    return get(owner_of(const_cast<void*>(object)));
  };
  if (field->set) {
    alias.set = [set = field->set, owner_of](void* object, const nlohmann::json& value) {
      set(owner_of(object), value);
    };
  }
  if (field->nested_of) {
    alias.nested_of = [nested_of = field->nested_of, owner_of](void* object) {
      return nested_of(owner_of(object));
    };
  }
  return alias;
}

const FieldInfo* FindFieldPath(const StructInfo& info, const std::string& key_path, void* object,
                               void** owner, std::string* canonical_path) {
  const size_t dot = key_path.find('.');
  const std::string key = key_path.substr(0, dot);
  const FieldInfo* field = info.Find(key);
  if (field == nullptr) field = info.FindAlias(key);
  if (field == nullptr) return nullptr;
  const std::string canonical = field->alias_of.empty() ? key : field->alias_of;
  if (dot == std::string::npos) {
    *owner = object;
    *canonical_path = canonical;
    return field;
  }
  if (field->kind != FieldKind::kStruct) return nullptr;
  const FieldInfo* inner = FindFieldPath(*field->nested, key_path.substr(dot + 1), field->nested_of(object),
                                         owner, canonical_path);
  if (inner != nullptr) *canonical_path = canonical + "." + *canonical_path;
  return inner;
}

nlohmann::ordered_json StructToJson(const StructInfo& info, const void* object) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  for (const FieldInfo& field : info.fields) {
    if (field.present && !field.present(object)) {  // an optional member holding nothing
      if (field.null_when_absent) json[field.key] = nullptr;
      continue;
    }
    json[field.key] = field.get(object);
  }
  return json;
}

namespace {

// Whether `json` has a value at the key path "inpaint.patch_radius".
bool HasPath(const nlohmann::json& json, const std::string& key_path) {
  const nlohmann::json* place = &json;
  for (size_t start = 0;;) {
    const size_t dot = key_path.find('.', start);
    const std::string key = key_path.substr(start, dot == std::string::npos ? dot : dot - start);
    if (!place->is_object() || !place->contains(key)) return false;
    place = &place->at(key);
    if (dot == std::string::npos) return true;
    start = dot + 1;
  }
}

}  // namespace

void StructFromJson(const StructInfo& info, const nlohmann::json& json, void* object,
                    const std::string& path) {
  if (!json.is_object()) {
    const std::string reason = fmt::format("expected an object of options, got {}", json.dump());
    if (path.empty()) throw OptionsError(reason);
    throw OptionsFieldError(path, reason);
  }
  for (const auto& [key, value] : json.items()) {
    const std::string key_path = Join(path, key);
    const FieldInfo* field = info.Find(key);
    if (field == nullptr) {
      field = info.FindAlias(key);
      // Both names of one field in one object: which one wins would depend on the keys' order.
      if (field != nullptr && HasPath(json, field->alias_of)) {
        throw OptionsFieldError(
            key_path, fmt::format("also given as {}; give one of the two", Join(path, field->alias_of)));
      }
    }
    if (field == nullptr) {
      std::vector<std::string> keys = info.Keys();
      for (const FieldInfo& alias : info.aliases) keys.push_back(alias.key);
      const std::string closest = ClosestMatch(key, keys);
      throw OptionsFieldError(
          key_path, fmt::format("unknown option{}",
                                closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest)));
    }
    if (value.is_null() && field->null_when_absent) {
      field->clear(object);
      continue;
    }
    try {
      field->CheckValue(value);
    } catch (const OptionsError& error) {
      throw OptionsFieldError(key_path, error.what());
    }
    if (field->kind == FieldKind::kStruct) {
      StructFromJson(*field->nested, value, field->nested_of(object), key_path);
    } else if (field->kind == FieldKind::kStructList) {
      try {
        field->set(object, value);
      } catch (const OptionsFieldError& error) {  // "[2].rms_px" inside the list
        throw OptionsFieldError(key_path + error.key_path(), error.reason());
      }
    } else {
      field->set(object, value);
    }
  }
  RunCheck(info, object, path);
}

namespace {

nlohmann::json SampleValue(const FieldInfo& field, const nlohmann::ordered_json& current) {
  const auto inside = [&](double value) {
    if (field.min && (field.min_exclusive ? value <= *field.min : value < *field.min)) return false;
    if (field.max && (field.max_exclusive ? value >= *field.max : value > *field.max)) return false;
    return true;
  };
  switch (field.kind) {
    case FieldKind::kBool:
      return !current.get<bool>();
    case FieldKind::kString:
      return current.get<std::string>() + "_sample";
    case FieldKind::kEnum: {
      const auto& choices = field.choices->choices;
      const int index = static_cast<int>(
          std::find_if(choices.begin(), choices.end(), [&](const auto& c) { return c.name == current; }) -
          choices.begin());
      return choices[(index + 1) % choices.size()].name;
    }
    case FieldKind::kUInt64:
      return current.get<uint64_t>() + 1234567890123ull;
    case FieldKind::kInt: {
      const int64_t value = current.get<int64_t>();
      for (int64_t candidate : {value + 1, value - 1, value + 2}) {
        if (inside(static_cast<double>(candidate)) && candidate >= field.integer_low &&
            candidate <= field.integer_high) {
          return candidate;
        }
      }
      return value;
    }
    case FieldKind::kDouble: {
      // A value with all 17 significant digits in use, to prove the round trip is exact.
      const double value = current.get<double>();
      for (double candidate : {value * 1.1 + 0.123456789012345, value * 0.9 + 1e-7, value * 0.5}) {
        if (inside(candidate)) return candidate;
      }
      if (field.min && field.max) return (*field.min + *field.max) / 3.0;
      return value;
    }
    case FieldKind::kNumberList:
      if (field.integer_elements) return nlohmann::json::array({1, 3, 7});
      for (double candidate : {0.1, 1.5, 2.0 / 3.0}) {
        if (!inside(candidate)) return current;
      }
      return nlohmann::json::array({0.1, 1.5, 2.0 / 3.0});
    case FieldKind::kStringList:
      return nlohmann::json::array({"sample one", "sample, two"});
    case FieldKind::kNumberMatrix: {  // 1, 2, 3, ... by rows, where the range allows them
      nlohmann::json rows = nlohmann::json::array();
      for (int r = 0; r < field.matrix_rows; ++r) {
        nlohmann::json row = nlohmann::json::array();
        for (int c = 0; c < field.matrix_cols; ++c) {
          const double value = 0.25 * (r * field.matrix_cols + c + 1);
          if (!inside(value)) return current;
          row.push_back(value);
        }
        rows.push_back(std::move(row));
      }
      return rows;
    }
    case FieldKind::kJson:
      return nlohmann::json{{"sample", nlohmann::json::array({1, "two"})}};
    case FieldKind::kStructList:  // one more element, of the element's defaults
      if (field.nested->default_json) {
        nlohmann::json list = current;
        list.push_back(nlohmann::json::parse(field.nested->default_json().dump()));
        return list;
      }
      break;
    case FieldKind::kStruct:
      break;
  }
  return current;
}

}  // namespace

namespace {

// `validate_root` checks the outermost struct: a nested field's sample may be valid for its own struct and
// not for the one holding it (FillOptions refuses InpaintOptions::stop_for_review).
int SetSamples(const StructInfo& info, void* object, const std::function<void()>& validate_root) {
  int changed = 0;
  for (const FieldInfo& field : info.fields) {
    if (field.kind == FieldKind::kStruct) {
      changed += SetSamples(*field.nested, field.nested_of(object), validate_root);
      continue;
    }
    const nlohmann::ordered_json before = field.get(object);
    const nlohmann::json sample = SampleValue(field, before);
    if (sample == nlohmann::json(before)) continue;
    field.set(object, sample);
    try {
      validate_root();
      ++changed;
    } catch (const OptionsError&) {
      field.set(object, before);
    }
  }
  return changed;
}

}  // namespace

int SetSampleValues(const StructInfo& info, void* object) {
  return SetSamples(info, object, [&] { ValidateStruct(info, object); });
}

std::string ValueText(const nlohmann::ordered_json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

}  // namespace lidarshop

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<SimdPath>() {
  static const EnumInfo info =
      MakeEnumInfo<SimdPath>("SIMD path", {{SimdPath::kScalar, "scalar", "baseline x86-64"},
                                           {SimdPath::kAvx2, "avx2", "AVX2 where the CPU has it"}});
  return info;
}

}  // namespace lidarshop
