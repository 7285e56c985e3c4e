// Command-line flags generated from the library's option descriptions (util/options.h), so that a flag's name,
// help, default, unit, range and choices come from one place, and a bad value is worded with the flag the user
// typed ("--patch-radius: 0 is out of range [1, 32]"), never with a struct's name.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lidarshop/util/options.h"

namespace lidarshop::cli {

// How a command shows the fields of one options struct.
struct BindSettings {
  // Keys to bind: "patch_radius", "poisson.solver" (a nested field), or an alias (util/options.h). Empty =
  // every top-level field and alias that is not a struct.
  std::vector<std::string> keys;
  std::vector<std::string> skip;  // keys left out of the default set
  // Flag names for keys whose flag is a contract of the command ("search_window_radius" -> "--window");
  // CLI11 syntax, so "-r,--radius" gives a short name too. Others are "--" + key with '-' for '_' and '.'.
  std::map<std::string, std::string> flags;
  std::string group;  // help section; "" = the command's options
  // Key path of this struct inside the command's options ("fill" for RemoveOptions::fill bound on its own), so
  // that an error about "fill.patch_radius" names the flag of "patch_radius".
  std::string prefix;
  // The values override another source (a scene file's scanner): help shows no default, and the command
  // applies only the fields the user set (OptionBinder::Given).
  bool overrides = false;
};

// Binds option structs to one command's CLI11 app, remembers which flag sets which key, and rewords
// OptionsFieldError with those flags.
//
// The first struct bound is the command's options: `--options FILE.json` sets any of its fields by key (the
// JSON form of util/options.h, e.g. {"patch_radius": 6, "acceptance": {"band_px": 3}}), flags on the same
// command line win over the file.
class OptionBinder {
 public:
  explicit OptionBinder(CLI::App& app);

  template <class S>
  void Bind(S* options, const BindSettings& settings = {}) {
    if (root_ == nullptr) {
      root_info_ = &InfoOf<S>();
      root_ = options;
    }
    BindStruct(InfoOf<S>(), options, settings);
  }

  // Validates `options` against its description and cross-field checks, naming the flag on failure.
  template <class S>
  void Validate(const S& options) const {
    try {
      lidarshop::Validate(options);
    } catch (const OptionsFieldError& error) {
      throw Reworded(error);
    }
  }

  // "--patch-radius" for "patch_radius" when bound, else the key path itself.
  std::string FlagOf(const std::string& key_path) const;
  // Names a hand-bound flag that sets `key_path` ("--x-range" for "x_min_m") in messages about that key.
  void NameFlag(const std::string& key_path, const std::string& flag) { flag_of_key_[key_path] = flag; }
  // The fields of the command's options set by --options or by a flag, as a JSON patch by key
  // ({"rows": 60, "seed": 3}); flags win over the file. For options that override another source.
  nlohmann::json Given() const;
  // The error with the flag the user typed in place of the key path.
  OptionsError Reworded(const OptionsFieldError& error) const;

 private:
  void BindStruct(const StructInfo& info, void* object, const BindSettings& settings);
  // `in_root`: the field is part of the command's options (the first struct bound), so Given() lists it.
  void BindField(const FieldInfo& field, void* object, const std::string& key_path,
                 const std::string& canonical_path, const BindSettings& settings, bool in_root);

  CLI::App& app_;
  std::map<std::string, std::string> flag_of_key_;
  // Fields of the command's options set by a flag (key path -> field and its struct), and the --options
  // file's JSON.
  std::map<std::string, std::pair<const FieldInfo*, const void*>> given_by_flag_;
  nlohmann::json given_by_file_ = nlohmann::json::object();
  const StructInfo* root_info_ = nullptr;
  void* root_ = nullptr;
};

// A CLI11 check that the value is one of `choices`' names ("'nope' is not a channel: range|rgb|... (did you
// mean ...?)"), for enums of undescribed structs bound by hand. `extra` names are accepted too.
CLI::Validator ChoiceOf(const EnumInfo& choices, std::vector<std::string> extra = {});

// Converts the text of a flag to the JSON value of a field of this kind (strict: "4x", "1e400", "yes" fail).
nlohmann::json ParseFlagValue(const FieldInfo& field, const std::string& text);

}  // namespace lidarshop::cli
