#include "lidarshop/util/options_markdown.h"

#include <deque>
#include <map>

#include <fmt/format.h>

namespace lidarshop {

namespace {

// Text inside a table cell: '|' would end the cell.
std::string Cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

// GitHub's anchor of a "### `Name`" heading.
std::string Anchor(const std::string& name) {
  std::string out;
  for (char c : name) out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string TypeText(const FieldInfo& field) {
  switch (field.kind) {
    case FieldKind::kBool:
      return "bool";
    case FieldKind::kInt:
    case FieldKind::kUInt64:
      return "integer";
    case FieldKind::kDouble:
      return "number";
    case FieldKind::kString:
      return "string";
    case FieldKind::kEnum: {
      std::string names;
      for (const EnumInfo::Choice& choice : field.choices->choices)
        names += fmt::format("{}`{}`", names.empty() ? "" : ", ", choice.name);
      return "one of " + names;
    }
    case FieldKind::kStruct:
      return fmt::format("[`{}`](#{})", field.nested->name, Anchor(field.nested->name));
    case FieldKind::kNumberList:
      return field.integer_elements ? "list of integers" : "list of numbers";
    case FieldKind::kStringList:
      return "list of strings";
    case FieldKind::kStructList:
      return fmt::format("list of [`{}`](#{})", field.nested->name, Anchor(field.nested->name));
    case FieldKind::kNumberMatrix:
      return fmt::format("{} × {} matrix (a list of rows)", field.matrix_rows, field.matrix_cols);
    case FieldKind::kJson:
      return "any JSON value";
  }
  return "";
}

std::string ValueCell(const nlohmann::ordered_json& value) {
  return fmt::format("`{}`", value.is_string() ? value.get<std::string>() : value.dump());
}

// "`patch_radius` 4, `acceptance.mean.enabled` true": where `value` differs from `base`, by key path.
void Differences(const nlohmann::ordered_json& value, const nlohmann::ordered_json& base,
                 const std::string& path, std::vector<std::string>* out) {
  for (const auto& [key, item] : value.items()) {
    const std::string key_path = path.empty() ? key : path + "." + key;
    if (!base.contains(key)) {
      out->push_back(fmt::format("`{}` {}", key_path, ValueCell(item)));
    } else if (item.is_object() && base.at(key).is_object()) {
      Differences(item, base.at(key), key_path, out);
    } else if (item != base.at(key)) {
      out->push_back(fmt::format("`{}` {}", key_path, ValueCell(item)));
    }
  }
}

// The field at a key path without aliases ("inpaint.patch_radius").
const FieldInfo* FieldAt(const StructInfo& info, const std::string& key_path) {
  const size_t dot = key_path.find('.');
  const FieldInfo* field = info.Find(key_path.substr(0, dot));
  if (field == nullptr || dot == std::string::npos) return field;
  return field->nested == nullptr ? nullptr : FieldAt(*field->nested, key_path.substr(dot + 1));
}

// The choices of the enums of a struct, one line each, below its table.
std::string ChoicesText(const StructInfo& info) {
  std::string out;
  for (const FieldInfo& field : info.fields) {
    if (field.kind != FieldKind::kEnum) continue;
    std::vector<std::string> choices;
    for (const EnumInfo::Choice& choice : field.choices->choices)
      choices.push_back(fmt::format("`{}` {}", choice.name, choice.doc));
    out += fmt::format("- `{}`: {}\n", field.key, fmt::join(choices, "; "));
  }
  return out;
}

}  // namespace

std::string MarkdownReference(const std::vector<TypeScriptStruct>& structs) {
  std::string out;
  VisitDescribedStructs(structs, [&out](const TypeScriptStruct& entry, const auto& push) {
    const StructInfo& info = *entry.info;
    const bool options = !entry.answer;
    // An options struct's own defaults; a result has none worth printing.
    const nlohmann::ordered_json defaults =
        options && info.default_json ? info.default_json() : nlohmann::ordered_json::object();
    std::string doc = info.doc;
    if (!doc.empty()) doc[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(doc[0])));
    out += fmt::format("\n### `{}`\n{} ({}).\n\n", info.name, doc, options ? "options" : "result");
    out += options ? "| key | type | default | unit | range | doc |\n|---|---|---|---|---|---|\n"
                   : "| key | type | unit | doc |\n|---|---|---|---|\n";
    for (const FieldInfo& field : info.fields) {
      if (!options) {
        // An optional part (FieldInfo::present) is left out of the JSON when the result has none.
        out += fmt::format("| `{}` | {}{} | {} | {} |\n", field.key, Cell(TypeText(field)),
                           field.null_when_absent ? ", or null"
                           : field.present        ? ", or absent"
                                                  : "",
                           Cell(field.unit), Cell(field.doc));
        if (field.kind == FieldKind::kStruct || field.kind == FieldKind::kStructList)
          push({field.nested, nullptr, true});
        continue;
      }
      std::string default_text;
      if (field.kind == FieldKind::kStruct) {
        // The holder may start the nested struct elsewhere than its own defaults (FillOptions::inpaint).
        std::vector<std::string> differences;
        if (defaults.contains(field.key) && field.nested->default_json)
          Differences(defaults.at(field.key), field.nested->default_json(), "", &differences);
        default_text = differences.empty() ? "its defaults" : fmt::format("{}", fmt::join(differences, ", "));
        push({field.nested, nullptr, false});
      } else {
        default_text = defaults.contains(field.key) ? ValueCell(defaults.at(field.key)) : "";
      }
      out += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", field.key, Cell(TypeText(field)),
                         Cell(default_text), Cell(field.unit), Cell(field.RangeText()), Cell(field.doc));
    }
    out += ChoicesText(info);
    if (!info.aliases.empty()) {
      std::vector<std::string> aliases;
      for (const FieldInfo& alias : info.aliases) {
        const FieldInfo* target = FieldAt(info, alias.alias_of);
        const bool narrower = target != nullptr && alias.RangeText() != target->RangeText();
        aliases.push_back(fmt::format("`{}` = `{}`{}", alias.key, alias.alias_of,
                                      narrower ? fmt::format(" (here {})", alias.RangeText()) : ""));
      }
      out += fmt::format(
          "\nOlder keys kept as aliases (accepted in JSON, as flags and in Python; never written): "
          "{}.\n",
          fmt::join(aliases, ", "));
    }
  });
  return out;
}

std::string ReplaceGeneratedPart(const std::string& page, const std::string& reference) {
  const size_t marker = page.find(kGeneratedMarker);
  if (marker == std::string::npos) {
    throw OptionsError(
        fmt::format("the page has no line \"{}\" ending its hand-written part", kGeneratedMarker));
  }
  return page.substr(0, marker + kGeneratedMarker.size()) + "\n" + reference;
}

}  // namespace lidarshop
