#include "lidarshop/cli/options_cli.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/input_file.h"

namespace lidarshop::cli {

namespace {

std::string DefaultFlag(const std::string& key_path) {
  std::string flag = "--" + key_path;
  std::replace(flag.begin(), flag.end(), '_', '-');
  std::replace(flag.begin(), flag.end(), '.', '-');
  return flag;
}

// The long name a user types, from CLI11 names like "-r,--radius".
std::string LongName(const std::string& names) {
  std::string best;
  size_t start = 0;
  while (start <= names.size()) {
    const size_t end = std::min(names.find(',', start), names.size());
    const std::string name = names.substr(start, end - start);
    if (best.empty() || name.rfind("--", 0) == 0) best = name;
    start = end + 1;
  }
  return best;
}

std::string HelpText(const FieldInfo& field) {
  std::string help = field.doc;
  std::vector<std::string> notes;
  if (!field.unit.empty()) notes.push_back(field.unit);
  if (!field.RangeText().empty()) notes.push_back(field.RangeText());
  if (!notes.empty()) help += fmt::format(" ({})", fmt::join(notes, ", "));
  return help;
}

std::string TypeName(const FieldInfo& field) {
  switch (field.kind) {
    case FieldKind::kEnum:
      return field.choices->NamesText();
    case FieldKind::kInt:
    case FieldKind::kUInt64:
      return "INT";
    case FieldKind::kDouble:
      return "NUMBER";
    case FieldKind::kNumberList:
      return "N,N,...";
    case FieldKind::kStringList:
      return "TEXT,TEXT,...";
    case FieldKind::kNumberMatrix:
      return fmt::format("N,N,... ({} by rows)", field.matrix_rows * field.matrix_cols);
    case FieldKind::kJson:
      return "JSON";
    default:
      return "TEXT";
  }
}

}  // namespace

nlohmann::json ParseFlagValue(const FieldInfo& field, const std::string& text) {
  switch (field.kind) {
    case FieldKind::kInt: {
      int64_t value = 0;
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (error != std::errc() || end != text.data() + text.size() || text.empty()) {
        throw OptionsError(fmt::format("'{}' is not a whole number", text));
      }
      return value;
    }
    case FieldKind::kUInt64: {
      uint64_t value = 0;
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (error != std::errc() || end != text.data() + text.size() || text.empty()) {
        throw OptionsError(fmt::format("'{}' is not a whole number >= 0", text));
      }
      return value;
    }
    case FieldKind::kDouble: {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value)) {
        throw OptionsError(fmt::format("'{}' is not a finite number", text));
      }
      return value;
    }
    case FieldKind::kBool:
      if (text == "true" || text == "1" || text == "on") return true;
      if (text == "false" || text == "0" || text == "off") return false;
      throw OptionsError(fmt::format("'{}' is not true or false", text));
    case FieldKind::kEnum:
    case FieldKind::kString:
      return text;
    case FieldKind::kNumberList: {
      nlohmann::json list = nlohmann::json::array();
      size_t start = 0;
      while (start <= text.size()) {
        const size_t end = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, end - start);
        char* item_end = nullptr;
        const double value = std::strtod(item.c_str(), &item_end);
        if (item.empty() || item_end != item.c_str() + item.size() || !std::isfinite(value)) {
          throw OptionsError(fmt::format("'{}' is not a comma-separated list of numbers", text));
        }
        list.push_back(value);
        start = end + 1;
      }
      return list;
    }
    case FieldKind::kStringList: {  // comma-separated, as number lists
      nlohmann::json list = nlohmann::json::array();
      size_t start = 0;
      while (start <= text.size()) {
        const size_t end = std::min(text.find(',', start), text.size());
        list.push_back(text.substr(start, end - start));
        start = end + 1;
      }
      return list;
    }
    case FieldKind::kNumberMatrix: {  // rows * columns numbers by rows, as a number list
      FieldInfo as_list = field;
      as_list.kind = FieldKind::kNumberList;
      const nlohmann::json numbers = ParseFlagValue(as_list, text);
      if (numbers.size() != size_t(field.matrix_rows) * size_t(field.matrix_cols)) {
        throw OptionsError(fmt::format("'{}' is not {} comma-separated numbers (a {} x {} matrix by rows)",
                                       text, field.matrix_rows * field.matrix_cols, field.matrix_rows,
                                       field.matrix_cols));
      }
      nlohmann::json rows = nlohmann::json::array();
      for (int r = 0; r < field.matrix_rows; ++r) {
        rows.push_back(nlohmann::json(numbers.begin() + r * field.matrix_cols,
                                      numbers.begin() + (r + 1) * field.matrix_cols));
      }
      return rows;
    }
    case FieldKind::kJson:
      try {
        return nlohmann::json::parse(text);
      } catch (const nlohmann::json::parse_error& error) {
        throw OptionsError(fmt::format("'{}' is not JSON: {}", text, error.what()));
      }
    case FieldKind::kStruct:
    case FieldKind::kStructList:
      break;
  }
  throw OptionsError("a group of options has no flag of its own");
}

CLI::Validator ChoiceOf(const EnumInfo& choices, std::vector<std::string> extra) {
  return CLI::Validator(
      [&choices, extra](std::string& text) -> std::string {
        if (std::find(extra.begin(), extra.end(), text) != extra.end()) return "";
        try {
          choices.Parse(text);
        } catch (const OptionsError& error) {
          return error.what();
        }
        return "";
      },
      choices.NamesText());
}

OptionBinder::OptionBinder(CLI::App& app) : app_(app) {
  // Defined before every bound flag: CLI11 runs option callbacks in definition order, so flags override it.
  app_.add_option_function<std::string>(
          "--options",
          [this](const std::string& path) {
            if (root_ == nullptr)
              throw CLI::ValidationError("--options", "this command has no options struct");
            // No output of this run may replace it (--json FILE naming the options file lost it).
            ProtectInput(path);
            try {
              const std::string text = ReadRegularFile(path);
              nlohmann::json json;
              try {
                json = nlohmann::json::parse(text);
              } catch (const nlohmann::json::exception& error) {  // syntax, or a number past double's range
                throw OptionsError(fmt::format("{}: not JSON: {}", path, error.what()));
              }
              StructFromJson(*root_info_, json, root_);
              given_by_file_.merge_patch(json);
            } catch (const OptionsFieldError& error) {
              throw CLI::ValidationError("--options", fmt::format("{}: {}", path, error.what()));
            } catch (const std::exception& error) {
              throw CLI::ValidationError("--options", error.what());
            }
          },
          "options as JSON (keys as in --json's \"options\"); flags given too win")
      ->type_name("FILE");
}

void OptionBinder::BindStruct(const StructInfo& info, void* object, const BindSettings& settings) {
  std::vector<std::string> keys = settings.keys;
  if (keys.empty()) {
    // Fields and aliases (a nested field's older flat key, util/options.h) in the order they were described,
    // so that the help lists the flags as it did before the nesting.
    const auto add = [&](const FieldInfo& field) {
      const bool skipped =
          std::find(settings.skip.begin(), settings.skip.end(), field.key) != settings.skip.end();
      if (field.kind != FieldKind::kStruct && field.kind != FieldKind::kStructList && !skipped)
        keys.push_back(field.key);
    };
    for (size_t i = 0; i <= info.fields.size(); ++i) {
      for (const FieldInfo& alias : info.aliases) {
        if (alias.position == i) add(alias);
      }
      if (i < info.fields.size()) add(info.fields[i]);
    }
  }
  for (const std::string& key_path : keys) {
    void* owner = nullptr;
    std::string canonical_path;
    const FieldInfo* field = FindFieldPath(info, key_path, object, &owner, &canonical_path);
    LIDARSHOP_CHECK(field != nullptr && field->kind != FieldKind::kStruct);
    BindField(*field, owner, key_path, canonical_path, settings, object == root_ || !settings.prefix.empty());
  }
}

void OptionBinder::BindField(const FieldInfo& field, void* object, const std::string& key_path,
                             const std::string& canonical_path, const BindSettings& settings, bool in_root) {
  const auto renamed = settings.flags.find(key_path);
  const std::string names = renamed != settings.flags.end() ? renamed->second : DefaultFlag(key_path);
  const std::string flag = LongName(names);
  // Errors name the field by its path without aliases ("inpaint.local_window_radius").
  const std::string full_path =
      settings.prefix.empty() ? canonical_path : settings.prefix + "." + canonical_path;
  flag_of_key_[full_path] = flag;
  const FieldInfo* info = &field;
  const auto set = [this, info, object, flag, full_path, in_root](const std::string& text) {
    try {
      const nlohmann::json value = ParseFlagValue(*info, text);
      info->CheckValue(value);
      info->set(object, value);
      if (in_root) given_by_flag_[full_path] = {info, object};
    } catch (const OptionsError& error) {
      throw CLI::ValidationError(flag, error.what());
    }
  };
  CLI::Option* option = nullptr;
  if (field.kind == FieldKind::kBool) {
    // --name sets true, --no-name false: a default of either kind can be turned around.
    const std::string negated = "--no-" + flag.substr(2);
    const bool initially = field.get(object).get<bool>();
    const bool say_default = !settings.overrides;
    option = app_.add_flag_callback(
        names, [set] { set("true"); }, HelpText(field) + (initially && say_default ? " (the default)" : ""));
    CLI::Option* off = app_.add_flag_callback(
        negated, [set] { set("false"); },
        fmt::format("turn {} off{}", flag, !initially && say_default ? " (the default)" : ""));
    if (!settings.group.empty()) off->group(settings.group);
  } else {
    option = app_.add_option_function<std::string>(names, set, HelpText(field));
    option->type_name(TypeName(field));
    if (!settings.overrides) option->default_str(ValueText(field.get(object)));
  }
  if (!settings.group.empty()) option->group(settings.group);
}

std::string OptionBinder::FlagOf(const std::string& key_path) const {
  const auto found = flag_of_key_.find(key_path);
  return found != flag_of_key_.end() ? found->second : key_path;
}

nlohmann::json OptionBinder::Given() const {
  nlohmann::json patch = given_by_file_;
  for (const auto& [key_path, bound] : given_by_flag_) {
    nlohmann::json* place = &patch;
    size_t start = 0;
    for (size_t dot = key_path.find('.'); dot != std::string::npos; dot = key_path.find('.', start)) {
      place = &(*place)[key_path.substr(start, dot - start)];
      start = dot + 1;
    }
    (*place)[key_path.substr(start)] = bound.first->get(bound.second);
  }
  return patch;
}

OptionsError OptionBinder::Reworded(const OptionsFieldError& error) const {
  return OptionsError(fmt::format("{}: {}", FlagOf(error.key_path()), error.reason()));
}

}  // namespace lidarshop::cli
