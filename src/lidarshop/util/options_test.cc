#include "lidarshop/util/options.h"

#include <gtest/gtest.h>

#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

enum class Flavour { kPlain, kSmoked, kDoubleSmoked };
struct InnerOptions {
  int band_px = 2;
  bool enabled = false;
};
struct OuterOptions {
  int patch_radius = 4;
  double sigma_m = 0.5;
  uint64_t seed = 0;
  Flavour flavour = Flavour::kPlain;
  std::string label = "scan";
  std::vector<float> weights;
  InnerOptions inner;
  int low = 0, high = 10;
};

template <>
const EnumInfo& EnumInfoOf<Flavour>() {
  static const EnumInfo info =
      MakeEnumInfo<Flavour>("flavour", {{Flavour::kPlain, "plain", ""},
                                        {Flavour::kSmoked, "smoked", ""},
                                        {Flavour::kDoubleSmoked, "double-smoked", ""}});
  return info;
}

template <>
const StructInfo& InfoOf<InnerOptions>() {
  static const StructInfo info = [] {
    StructBuilder<InnerOptions> b("InnerOptions", "inner");
    b.Field(&InnerOptions::band_px, "band_px", "band").Unit("px").Range(1, 64);
    b.Field(&InnerOptions::enabled, "enabled", "on");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<OuterOptions>() {
  static const StructInfo info = [] {
    StructBuilder<OuterOptions> b("OuterOptions", "outer");
    b.Field(&OuterOptions::patch_radius, "patch_radius", "radius").Unit("cells").Range(1, 15);
    b.Field(&OuterOptions::sigma_m, "sigma_m", "sigma").Unit("m").AboveZero();
    b.Field(&OuterOptions::seed, "seed", "seed");
    b.Field(&OuterOptions::flavour, "flavour", "flavour");
    b.Field(&OuterOptions::label, "label", "label");
    b.Field(&OuterOptions::weights, "weights", "weights").Min(0);
    b.Field(&OuterOptions::inner, "inner", "inner");
    b.Field(&OuterOptions::low, "low", "low");
    b.Field(&OuterOptions::high, "high", "high");
    b.Check([](const OuterOptions& o) {
      if (o.low >= o.high) throw OptionsFieldError("high", "must be above low");
    });
    return b.Build();
  }();
  return info;
}

// Options that nest OuterOptions and keep older flat keys as aliases (FillOptions keeps patch_radius for
// inpaint.patch_radius), one with a narrower range, one of a nested struct, one two levels down.
struct HolderOptions {
  OuterOptions outer;
  int count = 1;
};

template <>
const StructInfo& InfoOf<HolderOptions>() {
  static const StructInfo info = [] {
    StructBuilder<HolderOptions> b("HolderOptions", "holder");
    b.Field(&HolderOptions::outer, "outer", "outer");
    b.Alias("radius", "outer.patch_radius").Range(1, 8);
    b.Alias("inner", "outer.inner");
    b.Field(&HolderOptions::count, "count", "count").Min(0);
    b.Alias("band_px", "outer.inner.band_px");
    return b.Build();
  }();
  return info;
}

TEST(Options, AliasesSetTheNestedField) {
  const HolderOptions o = FromJson<HolderOptions>({{"radius", 5}, {"band_px", 7}, {"count", 3}});
  EXPECT_EQ(o.outer.patch_radius, 5);
  EXPECT_EQ(o.outer.inner.band_px, 7);
  EXPECT_EQ(o.count, 3);
  const HolderOptions n = FromJson<HolderOptions>({{"inner", {{"enabled", true}, {"band_px", 9}}}});
  EXPECT_TRUE(n.outer.inner.enabled);
  EXPECT_EQ(n.outer.inner.band_px, 9);
  // Written once, nested: the aliases are no keys of the JSON form, the description lists them apart.
  const nlohmann::ordered_json json = ToJson(o);
  EXPECT_EQ(json.size(), 2u);
  EXPECT_EQ(json["outer"]["patch_radius"], 5);
  EXPECT_FALSE(json.contains("radius"));
  const StructInfo& info = InfoOf<HolderOptions>();
  EXPECT_EQ(info.Keys(), (std::vector<std::string>{"outer", "count"}));
  EXPECT_EQ(info.AliasKeys(), (std::vector<std::string>{"radius", "inner", "band_px"}));
  EXPECT_EQ(info.FindAlias("radius")->kind, FieldKind::kInt);
  EXPECT_EQ(info.FindAlias("radius")->doc, "radius");  // the nested field's doc
  EXPECT_EQ(info.FindAlias("radius")->position, 1u);   // after "outer"
  EXPECT_EQ(info.FindAlias("band_px")->position, 2u);  // after "count"
  ExpectExactRoundTrip<HolderOptions>();
}

TEST(Options, AliasErrors) {
  // The alias's narrower range, through the alias and through the nested path.
  ExpectRejected<HolderOptions>({{"radius", 9}}, "radius", "9 is out of range [1, 8]");
  ExpectRejected<HolderOptions>({{"outer", {{"patch_radius", 9}}}}, "outer.patch_radius",
                                "9 is out of range [1, 8]");
  ExpectRejected<HolderOptions>({{"outer", {{"patch_radius", 16}}}}, "outer.patch_radius",
                                "16 is out of range [1, 15]");
  HolderOptions wide;
  wide.outer.patch_radius = 12;
  EXPECT_THROW(Validate(wide), OptionsFieldError);
  ExpectRejected<HolderOptions>({{"band_px", 0}}, "band_px", "out of range [1, 64]");
  ExpectRejected<HolderOptions>({{"inner", {{"band_pix", 3}}}}, "inner.band_pix", "did you mean 'band_px'");
  // Both names of one field.
  ExpectRejected<HolderOptions>({{"radius", 3}, {"outer", {{"patch_radius", 3}}}}, "radius",
                                "also given as outer.patch_radius");
  // A misspelt alias is suggested like a field.
  ExpectRejected<HolderOptions>({{"radus", 3}}, "radus", "did you mean 'radius'");
}

TEST(Options, FindFieldPathThroughAliases) {
  HolderOptions o;
  void* owner = nullptr;
  std::string canonical;
  const StructInfo& info = InfoOf<HolderOptions>();
  const FieldInfo* field = FindFieldPath(info, "inner.enabled", &o, &owner, &canonical);
  ASSERT_NE(field, nullptr);
  EXPECT_EQ(canonical, "outer.inner.enabled");
  EXPECT_EQ(owner, &o.outer.inner);
  field = FindFieldPath(info, "radius", &o, &owner, &canonical);
  ASSERT_NE(field, nullptr);
  EXPECT_EQ(canonical, "outer.patch_radius");
  field->set(owner, 6);  // through the alias's own struct
  EXPECT_EQ(o.outer.patch_radius, 6);
  EXPECT_EQ(field->get(owner), 6);
  EXPECT_EQ(FindFieldPath(info, "outer.flavour", &o, &owner, &canonical)->kind, FieldKind::kEnum);
  EXPECT_EQ(canonical, "outer.flavour");
  EXPECT_EQ(FindFieldPath(info, "radius.x", &o, &owner, &canonical), nullptr);
  EXPECT_EQ(FindFieldPath(info, "nothing", &o, &owner, &canonical), nullptr);
}

// A result whose parts only some runs have: std::optional members, left out of ToJson when empty.
struct PartialResult {
  int count = 0;
  std::optional<InnerOptions> stop;
  std::optional<int64_t> points;
  std::optional<double> size_px;
  std::optional<std::string> origin;
  std::optional<Flavour> flavour;
  double seconds = 0;
};

template <>
const StructInfo& InfoOf<PartialResult>() {
  static const StructInfo info = [] {
    StructBuilder<PartialResult> b("PartialResult", "partial");
    b.Field(&PartialResult::count, "count", "count");
    b.Field(&PartialResult::stop, "stop", "where it stopped");
    b.Field(&PartialResult::points, "points", "points").Min(0);
    b.Field(&PartialResult::size_px, "size_px", "size").Unit("px");
    b.Field(&PartialResult::origin, "origin", "origin");
    b.Field(&PartialResult::flavour, "flavour", "flavour");
    b.Field(&PartialResult::seconds, "seconds", "time").Unit("s");
    return b.Build();
  }();
  return info;
}

TEST(Options, OptionalFieldsAreWrittenOnlyWhenSet) {
  PartialResult result;
  result.count = 3;
  EXPECT_EQ(ToJson(result).dump(), R"({"count":3,"seconds":0.0})");
  result.stop = InnerOptions{5, true};
  result.points = 7;
  result.size_px = 2.5;
  result.origin = "spacing";
  result.flavour = Flavour::kSmoked;
  EXPECT_EQ(ToJson(result).dump(),
            R"({"count":3,"stop":{"band_px":5,"enabled":true},"points":7,"size_px":2.5,"origin":"spacing",)"
            R"("flavour":"smoked","seconds":0.0})");
  // Back from JSON: given keys set the member, absent ones leave it empty.
  const PartialResult back = FromJson<PartialResult>(nlohmann::json::parse(ToJson(result).dump()));
  EXPECT_EQ(ToJson(back).dump(), ToJson(result).dump());
  const PartialResult some = FromJson<PartialResult>({{"points", 4}, {"stop", {{"band_px", 3}}}});
  EXPECT_EQ(some.points, 4);
  ASSERT_TRUE(some.stop.has_value());
  EXPECT_EQ(some.stop->band_px, 3);
  EXPECT_FALSE(some.size_px.has_value());
  EXPECT_FALSE(some.flavour.has_value());
  // Ranges apply when a value is there.
  ExpectRejected<PartialResult>({{"points", -1}}, "points", "out of range");
  ExpectRejected<PartialResult>({{"stop", {{"band_px", 0}}}}, "stop.band_px", "out of range [1, 64]");
  PartialResult bad;
  EXPECT_NO_THROW(Validate(bad));
  bad.stop = InnerOptions{0, false};
  EXPECT_THROW(Validate(bad), OptionsFieldError);
  EXPECT_TRUE(InfoOf<PartialResult>().Find("stop")->present != nullptr);
  EXPECT_FALSE(InfoOf<PartialResult>().Find("count")->present != nullptr);
  ExpectExactRoundTrip<PartialResult>();
}

// A result holding a list of described structs (a resection's per-pair errors): a JSON array of objects.
struct ListResult {
  std::vector<InnerOptions> parts;
  int count = 0;
};

template <>
const StructInfo& InfoOf<ListResult>() {
  static const StructInfo info = [] {
    StructBuilder<ListResult> b("ListResult", "a list");
    b.Field(&ListResult::parts, "parts", "one per part");
    b.Field(&ListResult::count, "count", "count");
    return b.Build();
  }();
  return info;
}

TEST(Options, ListsOfStructsAreArraysOfObjects) {
  EXPECT_EQ(InfoOf<ListResult>().Find("parts")->kind, FieldKind::kStructList);
  EXPECT_EQ(InfoOf<ListResult>().Find("parts")->nested, &InfoOf<InnerOptions>());
  ListResult result;
  EXPECT_EQ(ToJson(result).dump(), R"({"parts":[],"count":0})");
  result.parts = {InnerOptions{3, true}, InnerOptions{}};
  result.count = 2;
  EXPECT_EQ(ToJson(result).dump(),
            R"({"parts":[{"band_px":3,"enabled":true},{"band_px":2,"enabled":false}],"count":2})");
  const ListResult back = FromJson<ListResult>(nlohmann::json::parse(ToJson(result).dump()));
  ASSERT_EQ(back.parts.size(), 2u);
  EXPECT_EQ(back.parts[0].band_px, 3);
  EXPECT_TRUE(back.parts[0].enabled);
  // An element's absent keys take the element's defaults, not the list's old element.
  ListResult base;
  base.parts = {InnerOptions{9, true}};
  const ListResult partial =
      FromJson<ListResult>(nlohmann::json::parse(R"({"parts":[{"enabled":true}]})"), base);
  ASSERT_EQ(partial.parts.size(), 1u);
  EXPECT_EQ(partial.parts[0].band_px, 2);
  // Errors name the element and its key.
  ExpectRejected<ListResult>(nlohmann::json::parse(R"({"parts":[{"band_px":1},{"band_px":0}]})"),
                             "parts[1].band_px", "out of range [1, 64]");
  ExpectRejected<ListResult>(nlohmann::json::parse(R"({"parts":[{"colour":1}]})"), "parts[0].colour",
                             "unknown option");
  ExpectRejected<ListResult>(nlohmann::json::parse(R"({"parts":[1,2]})"), "parts",
                             "expected a list of objects");
  ExpectRejected<ListResult>(nlohmann::json::parse(R"({"parts":{"band_px":1}})"), "parts",
                             "expected a list of objects");
  ListResult bad;
  bad.parts = {InnerOptions{}, InnerOptions{100, false}};
  try {
    Validate(bad);
    ADD_FAILURE() << "a bad element passed";
  } catch (const OptionsFieldError& error) {
    EXPECT_EQ(error.key_path(), "parts[1].band_px");
  }
  ExpectExactRoundTrip<ListResult>();
}

// A fixed-size matrix type as Eigen's looks to the description (RowsAtCompileTime, operator()).
struct Matrix2x3 {
  enum { RowsAtCompileTime = 2, ColsAtCompileTime = 3 };
  double values[6] = {1, 0, 0, 0, 1, 0};
  double& operator()(int r, int c) { return values[r * 3 + c]; }
  double operator()(int r, int c) const { return values[r * 3 + c]; }
};

// A result with the parts the schema needs beyond plain fields: a matrix, a part that is null when absent, lists
// and a string left out when empty, free-form JSON and a held struct listed flat.
struct ShapedResult {
  Matrix2x3 pose;
  std::optional<Matrix2x3> fit;
  std::optional<int> exit_code;
  std::optional<InnerOptions> stop;
  std::vector<std::string> warnings;
  std::string note;
  nlohmann::ordered_json payload;
};

struct FlatResult {
  int count = 0;
  InnerOptions inner;
  double seconds = 0;
};

template <>
const StructInfo& InfoOf<ShapedResult>() {
  static const StructInfo info = [] {
    StructBuilder<ShapedResult> b("ShapedResult", "shaped");
    b.Field(&ShapedResult::pose, "pose", "pose").Range(-10, 10);
    b.Field(&ShapedResult::fit, "fit", "fitted pose");
    b.Field(&ShapedResult::exit_code, "exit", "exit code").NullWhenAbsent();
    b.Field(&ShapedResult::stop, "stop", "where it stopped").NullWhenAbsent();
    b.Field(&ShapedResult::warnings, "warnings", "warnings").OmitWhenEmpty();
    b.Field(&ShapedResult::note, "note", "note").OmitWhenEmpty();
    b.Field(&ShapedResult::payload, "payload", "any value");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FlatResult>() {
  static const StructInfo info = [] {
    StructBuilder<FlatResult> b("FlatResult", "flat");
    b.Field(&FlatResult::count, "count", "count");
    b.Flatten(&FlatResult::inner);
    b.Field(&FlatResult::seconds, "seconds", "time").Unit("s");
    return b.Build();
  }();
  return info;
}

TEST(Options, MatricesAreListsOfRows) {
  const FieldInfo& pose = *InfoOf<ShapedResult>().Find("pose");
  EXPECT_EQ(pose.kind, FieldKind::kNumberMatrix);
  EXPECT_EQ(pose.matrix_rows, 2);
  EXPECT_EQ(pose.matrix_cols, 3);
  ShapedResult result;
  result.pose(1, 2) = 2.5;
  EXPECT_EQ(ToJson(result)["pose"].dump(), "[[1.0,0.0,0.0],[0.0,1.0,2.5]]");
  const ShapedResult back = FromJson<ShapedResult>(nlohmann::json::parse(R"({"pose":[[1,2,3],[4,5,6]]})"));
  EXPECT_EQ(back.pose(1, 0), 4);
  EXPECT_EQ(back.pose(0, 2), 3);
  ExpectRejected<ShapedResult>(nlohmann::json::parse(R"({"pose":[[1,2,3]]})"), "pose",
                               "expected 2 rows of 3");
  ExpectRejected<ShapedResult>(nlohmann::json::parse(R"({"pose":[[1,2,3],[4,5]]})"), "pose",
                               "expected 2 rows");
  ExpectRejected<ShapedResult>(nlohmann::json::parse(R"({"pose":[[1,2,3],[4,5,"6"]]})"), "pose",
                               "expected 2 rows");
  ExpectRejected<ShapedResult>(nlohmann::json::parse(R"({"pose":[[1,2,3],[4,5,60]]})"), "pose",
                               "60 is out of range [-10, 10]");
  // An optional matrix reads as zeros when empty, and is left out.
  EXPECT_FALSE(ToJson(result).contains("fit"));
  result.fit = Matrix2x3{};
  EXPECT_EQ(ToJson(result)["fit"].dump(), "[[1.0,0.0,0.0],[0.0,1.0,0.0]]");
}

TEST(Options, NullableFieldsAreAlwaysWritten) {
  ShapedResult result;
  nlohmann::ordered_json json = ToJson(result);
  ASSERT_TRUE(json.contains("exit"));
  EXPECT_TRUE(json["exit"].is_null());
  EXPECT_TRUE(json["stop"].is_null());
  result.exit_code = 3;
  result.stop = InnerOptions{5, true};
  json = ToJson(result);
  EXPECT_EQ(json["exit"], 3);
  EXPECT_EQ(json["stop"]["band_px"], 5);
  // null on input empties the member; a value sets it.
  ShapedResult base = result;
  const ShapedResult emptied =
      FromJson<ShapedResult>(nlohmann::json::parse(R"({"exit":null,"stop":null})"), base);
  EXPECT_FALSE(emptied.exit_code.has_value());
  EXPECT_FALSE(emptied.stop.has_value());
  const ShapedResult set =
      FromJson<ShapedResult>(nlohmann::json::parse(R"({"exit":0,"stop":{"band_px":4}})"));
  EXPECT_EQ(set.exit_code, 0);
  EXPECT_EQ(set.stop->band_px, 4);
  // Only a NullWhenAbsent field takes null.
  ExpectRejected<ShapedResult>(nlohmann::json::parse(R"({"fit":null})"), "fit", "expected 2 rows");
}

TEST(Options, EmptyListsAndStringsCanBeLeftOut) {
  ShapedResult result;
  EXPECT_FALSE(ToJson(result).contains("warnings"));
  EXPECT_FALSE(ToJson(result).contains("note"));
  result.warnings = {"one"};
  result.note = "n";
  EXPECT_EQ(ToJson(result)["warnings"].dump(), R"(["one"])");
  EXPECT_EQ(ToJson(result)["note"], "n");
  const FieldInfo& warnings = *InfoOf<ShapedResult>().Find("warnings");
  EXPECT_TRUE(warnings.present != nullptr);
  EXPECT_TRUE(warnings.clear == nullptr);  // not an optional member: absent reads as empty
}

TEST(Options, JsonFieldsHoldAnyValue) {
  ShapedResult result;
  EXPECT_TRUE(ToJson(result)["payload"].is_null());
  result.payload = nlohmann::ordered_json::parse(R"({"z":1,"a":[true,"x"]})");
  EXPECT_EQ(ToJson(result)["payload"].dump(), R"({"z":1,"a":[true,"x"]})");  // order kept
  const ShapedResult back = FromJson<ShapedResult>(nlohmann::json::parse(R"({"payload":[1,{"k":null}]})"));
  EXPECT_EQ(back.payload.dump(), R"([1,{"k":null}])");
  EXPECT_EQ(InfoOf<ShapedResult>().Find("payload")->kind, FieldKind::kJson);
  ExpectExactRoundTrip<ShapedResult>();
}

TEST(Options, FlattenListsTheHeldStructsFieldsAtTheHoldersLevel) {
  EXPECT_EQ(InfoOf<FlatResult>().Keys(),
            (std::vector<std::string>{"count", "band_px", "enabled", "seconds"}));
  FlatResult result;
  result.count = 2;
  result.inner.band_px = 7;
  EXPECT_EQ(ToJson(result).dump(), R"({"count":2,"band_px":7,"enabled":false,"seconds":0.0})");
  const FlatResult back = FromJson<FlatResult>(nlohmann::json::parse(R"({"enabled":true,"band_px":3})"));
  EXPECT_TRUE(back.inner.enabled);
  EXPECT_EQ(back.inner.band_px, 3);
  // The held struct's descriptions (ranges) apply.
  ExpectRejected<FlatResult>(nlohmann::json::parse(R"({"band_px":0})"), "band_px", "out of range [1, 64]");
  FlatResult bad;
  bad.inner.band_px = 100;
  EXPECT_THROW(Validate(bad), OptionsFieldError);
  ExpectExactRoundTrip<FlatResult>();
}

TEST(Options, RoundTripIsExact) {
  ExpectExactRoundTrip<OuterOptions>();
  OuterOptions o;
  o.sigma_m = 0.1 + 0.2;  // 0.30000000000000004: needs 17 digits
  o.seed = (uint64_t{1} << 63) + 5;
  o.weights = {0.1f, 3.0f};
  const OuterOptions back = FromJson<OuterOptions>(nlohmann::json::parse(ToJson(o).dump()));
  EXPECT_EQ(back.sigma_m, o.sigma_m);
  EXPECT_EQ(back.seed, o.seed);
  EXPECT_EQ(back.weights, o.weights);
}

TEST(Options, JsonFormUsesKeysAndEnumNames) {
  OuterOptions o;
  o.flavour = Flavour::kDoubleSmoked;
  const auto json = ToJson(o);
  EXPECT_EQ(json["flavour"], "double-smoked");
  EXPECT_EQ(json["inner"]["band_px"], 2);
  EXPECT_EQ(json.begin().key(), "patch_radius");  // declaration order
}

TEST(Options, AbsentKeysKeepTheBase) {
  OuterOptions base;
  base.patch_radius = 7;
  const OuterOptions o = FromJson<OuterOptions>(nlohmann::json{{"sigma_m", 2.0}}, base);
  EXPECT_EQ(o.patch_radius, 7);
  EXPECT_EQ(o.sigma_m, 2.0);
}

TEST(Options, ErrorsNameTheKey) {
  ExpectRejected<OuterOptions>({{"patch_radus", 3}}, "patch_radus", "did you mean 'patch_radius'");
  ExpectRejected<OuterOptions>({{"patch_radius", 0}}, "patch_radius", "out of range [1, 15]");
  ExpectRejected<OuterOptions>({{"patch_radius", 2.5}}, "patch_radius", "whole number");
  ExpectRejected<OuterOptions>({{"patch_radius", "4"}}, "patch_radius", "whole number");
  ExpectRejected<OuterOptions>({{"patch_radius", 5000000000}}, "patch_radius", "does not fit");
  ExpectRejected<OuterOptions>({{"sigma_m", 0}}, "sigma_m", "out of range > 0");
  ExpectRejected<OuterOptions>({{"sigma_m", true}}, "sigma_m", "expected a number");
  ExpectRejected<OuterOptions>({{"seed", -1}}, "seed", ">= 0");
  ExpectRejected<OuterOptions>({{"flavour", "smokd"}}, "flavour", "did you mean 'smoked'");
  ExpectRejected<OuterOptions>({{"flavour", 1}}, "flavour", "plain|smoked|double-smoked");
  ExpectRejected<OuterOptions>({{"weights", {1, -1}}}, "weights", "out of range >= 0");
  ExpectRejected<OuterOptions>({{"inner", {{"band_px", 0}}}}, "inner.band_px", "out of range [1, 64]");
  ExpectRejected<OuterOptions>({{"inner", {{"bandpx", 1}}}}, "inner.bandpx", "did you mean 'band_px'");
  ExpectRejected<OuterOptions>({{"inner", 3}}, "inner", "expected an object");
  ExpectRejected<OuterOptions>({{"low", 20}}, "high", "must be above low");
  EXPECT_THROW(FromJson<OuterOptions>(nlohmann::json::array()), OptionsError);
}

TEST(Options, ValidateChecksAnInstance) {
  OuterOptions o;
  EXPECT_NO_THROW(Validate(o));
  o.inner.band_px = 100;
  try {
    Validate(o);
    ADD_FAILURE();
  } catch (const OptionsFieldError& error) {
    EXPECT_EQ(error.key_path(), "inner.band_px");
  }
}

TEST(Options, EnumsConvertOneWay) {
  EXPECT_EQ(ToString(Flavour::kSmoked), "smoked");
  EXPECT_EQ(ParseEnum<Flavour>("double-smoked"), Flavour::kDoubleSmoked);
  EXPECT_THROW(ParseEnum<Flavour>("Smoked"), OptionsError);  // exact
  EXPECT_EQ(EnumInfoOf<Flavour>().NamesText(), "plain|smoked|double-smoked");
}

TEST(Options, ClosestMatch) {
  EXPECT_EQ(ClosestMatch("--chanel", {"--channel", "--output", "--scale"}), "--channel");
  EXPECT_EQ(ClosestMatch("--patch", {"--patch-radius", "--output"}), "--patch-radius");
  EXPECT_EQ(ClosestMatch("--zzzzzz", {"--channel", "--output"}), "");
}

TEST(Options, RangeText) {
  const StructInfo& info = InfoOf<OuterOptions>();
  EXPECT_EQ(info.Find("patch_radius")->RangeText(), "[1, 15]");
  EXPECT_EQ(info.Find("sigma_m")->RangeText(), "> 0");
  EXPECT_EQ(info.Find("seed")->RangeText(), "");
}

}  // namespace lidarshop
