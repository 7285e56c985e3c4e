// Test helpers for options descriptions (util/options.h); header-only, for *_test.cc files.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "lidarshop/util/options.h"

namespace lidarshop {

// Every field set to a sample value, written to JSON text, parsed back into a default struct: the two JSON
// forms must be identical (doubles print with all their digits, so equal text = equal values), and the
// description must cover every field it names with a doc line.
template <class S>
void ExpectExactRoundTrip() {
  const StructInfo& info = InfoOf<S>();
  S original;
  const int changed = SetSampleValues(info, &original);
  EXPECT_GT(changed, 0) << info.name << ": no field could take a sample value";
  const std::string text = ToJson(original).dump();
  const S parsed = FromJson<S>(nlohmann::json::parse(text));
  EXPECT_EQ(ToJson(parsed).dump(), text) << info.name;
  EXPECT_NE(ToJson(S{}).dump(), text) << info.name << ": the sample equals the defaults";
  for (const FieldInfo& field : info.fields) {
    EXPECT_FALSE(field.doc.empty()) << info.name << "." << field.key << " has no doc line";
  }
  EXPECT_NO_THROW(Validate(S{})) << info.name << ": the defaults are not valid";
}

// FromJson({key: value}) throws an OptionsFieldError whose key path is `key` and
// whose message contains `expected`.
template <class S>
void ExpectRejected(const nlohmann::json& json, const std::string& key_path, const std::string& expected) {
  try {
    FromJson<S>(json);
    ADD_FAILURE() << json.dump() << " was accepted";
  } catch (const OptionsFieldError& error) {
    EXPECT_EQ(error.key_path(), key_path) << error.what();
    EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
  }
}

}  // namespace lidarshop
