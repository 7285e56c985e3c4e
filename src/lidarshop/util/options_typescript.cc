#include "lidarshop/util/options_typescript.h"

#include <algorithm>
#include <deque>
#include <map>

#include <fmt/format.h>

namespace lidarshop {

namespace {

constexpr size_t kPrintWidth = 110;  // web/.prettierrc.json

std::string KindName(FieldKind kind) {
  switch (kind) {
    case FieldKind::kBool:
      return "bool";
    case FieldKind::kInt:
      return "int";
    case FieldKind::kUInt64:
      return "uint64";
    case FieldKind::kDouble:
      return "double";
    case FieldKind::kString:
      return "string";
    case FieldKind::kEnum:
      return "enum";
    case FieldKind::kStruct:
      return "struct";
    case FieldKind::kNumberList:
      return "number_list";
    case FieldKind::kStringList:
      return "string_list";
    case FieldKind::kStructList:
      return "struct_list";
    case FieldKind::kNumberMatrix:
      return "number_matrix";
    case FieldKind::kJson:
      return "json";
  }
  return "";
}

// A TypeScript string literal in single quotes (Prettier's choice with singleQuote).
std::string Quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'' || c == '\\') out += '\\';
    out += c;
  }
  return out + "'";
}

// The member's type as a list of union alternatives (one for every kind but enums).
std::vector<std::string> TypeAlternatives(const FieldInfo& field, bool answer) {
  switch (field.kind) {
    case FieldKind::kBool:
      return {"boolean"};
    case FieldKind::kInt:
    case FieldKind::kUInt64:
      return {"number"};
    case FieldKind::kDouble:
      if (answer) return {"number", "null"};
      return {"number"};
    case FieldKind::kString:
      return {"string"};
    case FieldKind::kEnum: {
      std::vector<std::string> names;
      for (const EnumInfo::Choice& choice : field.choices->choices) names.push_back(Quoted(choice.name));
      return names;
    }
    case FieldKind::kStruct:
      return {field.nested->name};
    case FieldKind::kNumberList:
      return {answer && !field.integer_elements ? "(number | null)[]" : "number[]"};
    case FieldKind::kStringList:
      return {"string[]"};
    case FieldKind::kStructList:
      return {field.nested->name + "[]"};
    case FieldKind::kNumberMatrix:
      return {answer ? "(number | null)[][]" : "number[][]"};
    case FieldKind::kJson:
      return {"unknown"};
  }
  return {"unknown"};
}

// "patch half-width; patches are 2r+1 wide [cells] in [1, 15], default 4".
std::string MemberComment(const FieldInfo& field, const nlohmann::ordered_json* defaults) {
  std::string text = field.doc;
  if (!field.unit.empty()) text += fmt::format(" [{}]", field.unit);
  const std::string range = field.RangeText();
  if (!range.empty()) text += " in " + range;
  if (field.kind == FieldKind::kEnum) {
    text += ": ";
    for (size_t i = 0; i < field.choices->choices.size(); ++i) {
      const EnumInfo::Choice& choice = field.choices->choices[i];
      text += fmt::format("{}{} ({})", i ? ", " : "", choice.name, choice.doc);
    }
  }
  if (defaults != nullptr && defaults->is_object() && defaults->contains(field.key) &&
      field.kind != FieldKind::kStruct && field.kind != FieldKind::kStructList) {
    text += ", default " + ValueText(defaults->at(field.key));
  }
  return text;
}

// One member as Prettier prints it: on one line when it fits, else a union broken before each '|'.
// An optional member (FieldInfo::present) is `key?:`, absent from the JSON when the result has none.
// A NullWhenAbsent member is always there, `| null` when absent.
void AppendMember(const FieldInfo& field, std::vector<std::string> alternatives, std::string* out) {
  const std::string key = field.present && !field.null_when_absent ? field.key + "?" : field.key;
  if (field.null_when_absent &&
      std::find(alternatives.begin(), alternatives.end(), "null") == alternatives.end())
    alternatives.push_back("null");
  std::string one_line = fmt::format("  {}: {};", key, fmt::join(alternatives, " | "));
  if (one_line.size() <= kPrintWidth || alternatives.size() == 1) {
    *out += one_line + "\n";
    return;
  }
  *out += fmt::format("  {}:\n", key);
  for (size_t i = 0; i < alternatives.size(); ++i) {
    *out += fmt::format("    | {}{}\n", alternatives[i], i + 1 == alternatives.size() ? ";" : "");
  }
}

}  // namespace

void VisitDescribedStructs(
    const std::vector<TypeScriptStruct>& structs,
    const std::function<void(const TypeScriptStruct&, const std::function<void(TypeScriptStruct)>&)>& visit) {
  std::deque<TypeScriptStruct> queue(structs.begin(), structs.end());
  std::map<std::string, const StructInfo*> visited;
  const std::function<void(TypeScriptStruct)> push = [&queue](TypeScriptStruct nested) {
    queue.push_back(std::move(nested));
  };
  while (!queue.empty()) {
    const TypeScriptStruct entry = queue.front();
    queue.pop_front();
    const StructInfo& info = *entry.info;
    if (const auto found = visited.find(info.name); found != visited.end()) {
      if (found->second != &info)
        throw OptionsError(fmt::format("two described structs are named {}", info.name));
      continue;
    }
    visited[info.name] = &info;
    visit(entry, push);
  }
}

std::string TypeScriptDeclarations(const std::vector<TypeScriptStruct>& structs, std::string_view header) {
  std::string out(header);
  if (!out.empty() && out.back() != '\n') out += '\n';
  VisitDescribedStructs(structs, [&out](const TypeScriptStruct& entry, const auto& push) {
    const StructInfo& info = *entry.info;
    const nlohmann::ordered_json* defaults = entry.defaults.is_object() ? &entry.defaults : nullptr;
    out += fmt::format("\n// {} (C++ {})\nexport interface {} {{\n", info.doc, info.name, info.name);
    for (const FieldInfo& field : info.fields) {
      out += "  // " + MemberComment(field, defaults) + "\n";
      AppendMember(field, TypeAlternatives(field, entry.answer), &out);
      if (field.kind == FieldKind::kStruct) {
        TypeScriptStruct nested{field.nested, nullptr, entry.answer};
        if (defaults != nullptr && defaults->contains(field.key)) nested.defaults = defaults->at(field.key);
        push(std::move(nested));
      } else if (field.kind == FieldKind::kStructList) {
        push(TypeScriptStruct{field.nested, nullptr, entry.answer});
      }
    }
    out += "}\n";
  });
  return out;
}

nlohmann::ordered_json DescriptionJson(const StructInfo& info) {
  nlohmann::ordered_json fields = nlohmann::ordered_json::array();
  for (const FieldInfo& field : info.fields) {
    nlohmann::ordered_json json = {{"key", field.key},
                                   {"kind", KindName(field.kind)},
                                   {"doc", field.doc},
                                   {"unit", field.unit},
                                   {"range", field.RangeText()}};
    if (field.choices != nullptr) {
      nlohmann::ordered_json names = nlohmann::ordered_json::array();
      for (const EnumInfo::Choice& choice : field.choices->choices) names.push_back(choice.name);
      json["choices"] = names;
    }
    if (field.null_when_absent) {
      json["nullable"] = true;  // null when absent
    } else if (field.present) {
      json["optional"] = true;  // left out of the JSON when absent
    }
    if (field.kind == FieldKind::kNumberMatrix) json["shape"] = {field.matrix_rows, field.matrix_cols};
    if (field.nested != nullptr) json["struct"] = DescriptionJson(*field.nested);
    fields.push_back(std::move(json));
  }
  nlohmann::ordered_json description = {{"name", info.name}, {"doc", info.doc}, {"fields", fields}};
  if (!info.aliases.empty()) {
    nlohmann::ordered_json aliases = nlohmann::ordered_json::array();
    for (const FieldInfo& alias : info.aliases) {
      aliases.push_back({{"key", alias.key}, {"alias_of", alias.alias_of}, {"range", alias.RangeText()}});
    }
    description["aliases"] = std::move(aliases);
  }
  return description;
}

nlohmann::ordered_json SchemaJson(const std::vector<TypeScriptStruct>& structs) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const TypeScriptStruct& entry : structs) {
    nlohmann::ordered_json description = DescriptionJson(*entry.info);
    description["result"] = entry.answer;
    list.push_back(std::move(description));
  }
  return {{"structs", std::move(list)}};
}

}  // namespace lidarshop
