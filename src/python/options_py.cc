#include "options_py.h"

namespace lidarshop::python {

std::map<const StructInfo*, NestedCaster>& NestedCasters() {
  static std::map<const StructInfo*, NestedCaster> casters;
  return casters;
}

namespace {

std::string PythonLiteral(const nlohmann::ordered_json& value) {
  if (value.is_null()) return "None";
  if (value.is_boolean()) return value.get<bool>() ? "True" : "False";
  if (value.is_string()) return "'" + value.get<std::string>() + "'";
  return ValueText(value);
}

}  // namespace

std::string FieldDoc(const FieldInfo& field, const nlohmann::ordered_json& default_value) {
  std::string doc = field.doc;
  if (!field.unit.empty()) doc += fmt::format(" [{}]", field.unit);
  const std::string range = field.RangeText();
  const bool elements = field.kind == FieldKind::kNumberList || field.kind == FieldKind::kNumberMatrix;
  if (!range.empty()) doc += fmt::format(", {}{}", elements ? "each " : "", range);
  if (field.kind == FieldKind::kNumberMatrix)
    doc += fmt::format(", a {} x {} matrix as a list of rows", field.matrix_rows, field.matrix_cols);
  if (field.clear) doc += ", or None";
  if (field.kind == FieldKind::kEnum) {
    doc += fmt::format(", one of {}", field.choices->NamesText(", "));
    for (const EnumInfo::Choice& choice : field.choices->choices) {
      doc += fmt::format("\n  '{}': {}", choice.name, choice.doc);
    }
    doc += fmt::format("\ndefault {}", PythonLiteral(default_value));
  } else if (field.kind == FieldKind::kStruct) {
    doc += fmt::format(" ({})", field.nested->name);
  } else if (field.kind == FieldKind::kStructList) {
    doc += fmt::format(" (a list of {})", field.nested->name);
  } else {
    doc += fmt::format(", default {}", PythonLiteral(default_value));
  }
  return doc;
}

std::string StructDoc(const StructInfo& info, const void* defaults) {
  std::string doc = info.doc;
  if (!doc.empty()) doc[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(doc[0])));
  doc += ".\n\nFields:\n";
  for (const FieldInfo& field : info.fields) {
    std::string line = FieldDoc(field, field.get(defaults));
    // One line per field in the class doc; the attribute's own doc has the choices.
    line = line.substr(0, line.find('\n'));
    doc += fmt::format("  {}: {}\n", field.key, line);
  }
  if (!info.aliases.empty()) {
    doc += "\nAliases (older keys, read and set the nested field):\n";
    for (const FieldInfo& alias : info.aliases) doc += fmt::format("  {}: {}\n", alias.key, alias.alias_of);
  }
  return doc;
}

std::string StructRepr(const StructInfo& info, const void* object) {
  std::string text = info.name + "(";
  bool first = true;
  for (const FieldInfo& field : info.fields) {
    text += first ? "" : ", ";
    first = false;
    if (field.clear && !field.present(object)) {
      text += field.key + "=None";
    } else if (field.kind == FieldKind::kStruct) {
      text += field.key + "=" + StructRepr(*field.nested, field.nested_of(const_cast<void*>(object)));
    } else {
      const auto value = field.get(object);
      text += field.key + "=" + (value.is_array() ? value.dump() : PythonLiteral(value));
    }
  }
  return text + ")";
}

void SetField(const StructInfo& info, const FieldInfo& field, void* object, const py::handle& value) {
  if (value.is_none() && field.clear) {  // an optional member: None empties it
    field.clear(object);
    return;
  }
  const nlohmann::json json = ToJsonValue(value);
  if (field.kind == FieldKind::kStruct || field.kind == FieldKind::kStructList) {
    // An options object (to_dict) replaces every nested field; a dict sets the keys it names. Errors name
    // the key path ("poisson.tolerance: ...").
    nlohmann::json patch = nlohmann::json::object();
    patch[field.key] = json;
    StructFromJson(info, patch, object);
    return;
  }
  try {
    field.CheckValue(json);
  } catch (const OptionsFieldError&) {
    throw;
  } catch (const OptionsError& error) {
    throw OptionsFieldError(field.key, error.what());
  }
  field.set(object, json);
}

py::object GetField(const FieldInfo& field, void* object, py::handle parent) {
  if (field.clear && !field.present(object)) return py::none();  // an optional member holding nothing
  if (field.kind == FieldKind::kStruct) {
    const auto caster = NestedCasters().find(field.nested);
    if (caster == NestedCasters().end()) {
      // A described struct nobody bound: still readable, as a dict.
      return FromJsonValue(field.get(object));
    }
    return caster->second(field.nested_of(object), parent);
  }
  if (field.kind == FieldKind::kStructList) {
    const auto caster = NestedCasters().find(field.nested);
    if (caster == NestedCasters().end()) return FromJsonValue(field.get(object));  // a list of dicts
    py::list list;
    for (size_t i = 0; i < field.list_size(object); ++i)
      list.append(caster->second(field.element_of(object, i), parent));
    return list;
  }
  return FromJsonValue(field.get(object));
}

void ApplyDict(const StructInfo& info, const py::handle& dict, void* object) {
  StructFromJson(info, ToJsonValue(dict), object);
}

}  // namespace lidarshop::python
