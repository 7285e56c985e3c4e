#include "lidarshop/util/options_typescript.h"

#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidarshop/util/options.h"

namespace lidarshop {

enum class Shade { kLight, kDark };
struct LeafOptions {
  int band_px = 2;
};
struct TreeOptions {
  Shade shade = Shade::kDark;
  double sigma_m = 0.5;
  std::vector<int> counts;
  LeafOptions leaf;
};
struct TreeResult {
  double rms_m = 0;
  std::vector<std::string> warnings;
  std::optional<LeafOptions> fallen;  // some results only
};

template <>
const EnumInfo& EnumInfoOf<Shade>() {
  static const EnumInfo info =
      MakeEnumInfo<Shade>("shade", {{Shade::kLight, "light", "pale"}, {Shade::kDark, "dark", "deep"}});
  return info;
}

template <>
const StructInfo& InfoOf<LeafOptions>() {
  static const StructInfo info = [] {
    StructBuilder<LeafOptions> b("LeafOptions", "a leaf");
    b.Field(&LeafOptions::band_px, "band_px", "band").Unit("px").Range(1, 64);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<TreeOptions>() {
  static const StructInfo info = [] {
    StructBuilder<TreeOptions> b("TreeOptions", "a tree");
    b.Field(&TreeOptions::shade, "shade", "its shade");
    b.Field(&TreeOptions::sigma_m, "sigma_m", "noise").Unit("m").AboveZero();
    b.Field(&TreeOptions::counts, "counts", "per branch");
    b.Field(&TreeOptions::leaf, "leaf", "its leaf");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<TreeResult>() {
  static const StructInfo info = [] {
    StructBuilder<TreeResult> b("TreeResult", "what came out");
    b.Field(&TreeResult::rms_m, "rms_m", "fit").Unit("m");
    b.Field(&TreeResult::warnings, "warnings", "one sentence each");
    b.Field(&TreeResult::fallen, "fallen", "a leaf that fell (some results only)");
    return b.Build();
  }();
  return info;
}

TEST(OptionsTypeScript, InterfacesFromTheDescriptions) {
  const std::string text =
      TypeScriptDeclarations({OptionsType<TreeOptions>(), ResultType<TreeResult>()}, "// header\n");
  EXPECT_EQ(text,
            "// header\n"
            "\n// a tree (C++ TreeOptions)\n"
            "export interface TreeOptions {\n"
            "  // its shade: light (pale), dark (deep), default dark\n"
            "  shade: 'light' | 'dark';\n"
            "  // noise [m] in > 0, default 0.5\n"
            "  sigma_m: number;\n"
            "  // per branch, default []\n"
            "  counts: number[];\n"
            "  // its leaf\n"
            "  leaf: LeafOptions;\n"
            "}\n"
            "\n// what came out (C++ TreeResult)\n"
            "export interface TreeResult {\n"
            "  // fit [m]\n"
            "  rms_m: number | null;\n"
            "  // one sentence each\n"
            "  warnings: string[];\n"
            "  // a leaf that fell (some results only)\n"
            "  fallen?: LeafOptions;\n"
            "}\n"
            "\n// a leaf (C++ LeafOptions)\n"
            "export interface LeafOptions {\n"
            "  // band [px] in [1, 64], default 2\n"
            "  band_px: number;\n"
            "}\n");
}

TEST(OptionsTypeScript, LongUnionsBreakAsPrettierDoes) {
  FieldInfo field;
  field.key = "method";
  field.kind = FieldKind::kEnum;
  EnumInfo many{"many", {}};
  for (int i = 0; i < 12; ++i) many.choices.push_back({i, "choice-number-" + std::to_string(i), ""});
  field.choices = &many;
  StructInfo info{"Wide", "wide", {field}, nullptr};
  const std::string text = TypeScriptDeclarations({{&info, nullptr, false}}, "");
  EXPECT_NE(text.find("  method:\n    | 'choice-number-0'\n    | 'choice-number-1'\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("    | 'choice-number-11';\n}"), std::string::npos) << text;
}

// A result with a list of described structs: `LeafOptions[]`, and the element's interface declared once.
struct ForestResult {
  std::vector<LeafOptions> leaves;
};

template <>
const StructInfo& InfoOf<ForestResult>() {
  static const StructInfo info = [] {
    StructBuilder<ForestResult> b("ForestResult", "a forest");
    b.Field(&ForestResult::leaves, "leaves", "every leaf");
    return b.Build();
  }();
  return info;
}

TEST(OptionsTypeScript, ListsOfStructsAreArraysOfTheirInterface) {
  const std::string out = TypeScriptDeclarations({ResultType<ForestResult>()}, "");
  EXPECT_NE(out.find("  leaves: LeafOptions[];\n"), std::string::npos) << out;
  EXPECT_NE(out.find("export interface LeafOptions {"), std::string::npos) << out;
  const nlohmann::ordered_json json = DescriptionJson(InfoOf<ForestResult>());
  EXPECT_EQ(json["fields"][0]["kind"], "struct_list");
  EXPECT_EQ(json["fields"][0]["struct"]["name"], "LeafOptions");
}

// A matrix, a part that is null when absent, a list left out when empty and free-form JSON.
struct Grid2x2 {
  enum { RowsAtCompileTime = 2, ColsAtCompileTime = 2 };
  double values[4] = {};
  double& operator()(int r, int c) { return values[r * 2 + c]; }
  double operator()(int r, int c) const { return values[r * 2 + c]; }
};
struct ShapesResult {
  Grid2x2 pose;
  std::optional<int> exit_code;
  std::vector<std::string> warnings;
  nlohmann::ordered_json payload;
};

template <>
const StructInfo& InfoOf<ShapesResult>() {
  static const StructInfo info = [] {
    StructBuilder<ShapesResult> b("ShapesResult", "shapes");
    b.Field(&ShapesResult::pose, "pose", "pose");
    b.Field(&ShapesResult::exit_code, "exit", "exit code").NullWhenAbsent();
    b.Field(&ShapesResult::warnings, "warnings", "warnings").OmitWhenEmpty();
    b.Field(&ShapesResult::payload, "payload", "any value");
    return b.Build();
  }();
  return info;
}

TEST(OptionsTypeScript, MatricesNullablesOmittedListsAndJson) {
  const std::string out = TypeScriptDeclarations({ResultType<ShapesResult>()}, "");
  EXPECT_NE(out.find("  pose: (number | null)[][];\n"), std::string::npos) << out;
  EXPECT_NE(out.find("  exit: number | null;\n"), std::string::npos) << out;
  EXPECT_NE(out.find("  warnings?: string[];\n"), std::string::npos) << out;
  EXPECT_NE(out.find("  payload: unknown;\n"), std::string::npos) << out;
  const nlohmann::ordered_json json = DescriptionJson(InfoOf<ShapesResult>());
  EXPECT_EQ(json["fields"][0]["kind"], "number_matrix");
  EXPECT_EQ(json["fields"][0]["shape"].dump(), "[2,2]");
  EXPECT_EQ(json["fields"][1]["nullable"], true);
  EXPECT_FALSE(json["fields"][1].contains("optional"));
  EXPECT_EQ(json["fields"][2]["optional"], true);
  EXPECT_EQ(json["fields"][3]["kind"], "json");
}

TEST(OptionsTypeScript, TwoStructsOfOneNameThrow) {
  StructInfo a{"Same", "a", {}, nullptr}, b{"Same", "b", {}, nullptr};
  EXPECT_THROW(TypeScriptDeclarations({{&a, nullptr, false}, {&b, nullptr, false}}, ""), OptionsError);
}

TEST(OptionsTypeScript, DescriptionJsonNestsStructs) {
  const nlohmann::ordered_json json = DescriptionJson(InfoOf<TreeOptions>());
  EXPECT_EQ(json["name"], "TreeOptions");
  EXPECT_EQ(json["fields"][0]["choices"], nlohmann::ordered_json::array({"light", "dark"}));
  EXPECT_EQ(json["fields"][1]["range"], "> 0");
  EXPECT_EQ(json["fields"][3]["struct"]["fields"][0]["key"], "band_px");
}

// `schema --json`: the structs in the order given, each marked as a result or as options.
TEST(OptionsTypeScript, SchemaJsonListsTheStructsAndMarksResults) {
  const nlohmann::ordered_json json = SchemaJson({OptionsType<TreeOptions>(), ResultType<TreeResult>()});
  ASSERT_EQ(json["structs"].size(), 2u);
  EXPECT_EQ(json["structs"][0]["name"], "TreeOptions");
  EXPECT_EQ(json["structs"][0]["result"], false);
  EXPECT_EQ(json["structs"][1]["name"], "TreeResult");
  EXPECT_EQ(json["structs"][1]["result"], true);
  EXPECT_EQ(json["structs"][1]["fields"], DescriptionJson(InfoOf<TreeResult>())["fields"]);
}

// A std::optional member is marked optional (left out of the JSON when absent); the others have no such key.
TEST(OptionsTypeScript, DescriptionJsonMarksOptionalFields) {
  const nlohmann::ordered_json json = DescriptionJson(InfoOf<TreeResult>());
  EXPECT_FALSE(json["fields"][0].contains("optional"));
  EXPECT_EQ(json["fields"][2]["optional"], true);
  EXPECT_EQ(json["fields"][2]["struct"]["name"], "LeafOptions");
}

}  // namespace lidarshop
