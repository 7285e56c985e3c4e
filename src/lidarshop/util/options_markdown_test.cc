#include "lidarshop/util/options_markdown.h"

#include <gtest/gtest.h>

namespace lidarshop {

struct PartOptions {
  int band_px = 2;
};
struct WholeOptions {
  PartOptions part{.band_px = 5};  // the holder starts its part elsewhere than the part's defaults
  double sigma_m = 0.5;
};

template <>
const StructInfo& InfoOf<PartOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PartOptions> b("PartOptions", "part");
    b.Field(&PartOptions::band_px, "band_px", "band | width").Unit("px").Range(1, 64);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<WholeOptions>() {
  static const StructInfo info = [] {
    StructBuilder<WholeOptions> b("WholeOptions", "whole");
    b.Field(&WholeOptions::part, "part", "the part");
    b.Alias("band_px", "part.band_px").Range(1, 8);
    b.Field(&WholeOptions::sigma_m, "sigma_m", "sigma").Unit("m").AboveZero();
    return b.Build();
  }();
  return info;
}

TEST(OptionsMarkdown, OneSectionPerStructWithDefaultsAndAliases) {
  const std::string text = MarkdownReference({OptionsType<WholeOptions>(), OptionsType<PartOptions>()});
  EXPECT_NE(text.find("### `WholeOptions`"), std::string::npos);
  // The nested struct once, though listed and nested.
  const size_t part = text.find("### `PartOptions`");
  ASSERT_NE(part, std::string::npos);
  EXPECT_EQ(text.find("### `PartOptions`", part + 1), std::string::npos);
  // Its own default, and the holder's different start named in the holder's row.
  EXPECT_NE(text.find("| `band_px` | integer | `2` | px | [1, 64] | band \\| width |"), std::string::npos)
      << text;
  EXPECT_NE(text.find("| `part` | [`PartOptions`](#partoptions) | `band_px` `5` |"), std::string::npos)
      << text;
  EXPECT_NE(text.find("| `sigma_m` | number | `0.5` | m | > 0 | sigma |"), std::string::npos) << text;
  EXPECT_NE(text.find("`band_px` = `part.band_px` (here [1, 8])"), std::string::npos) << text;
}

TEST(OptionsMarkdown, TheHandWrittenPartStays) {
  const std::string page = "# Title\nprose\n" + std::string(kGeneratedMarker) + "\nold reference\n";
  EXPECT_EQ(ReplaceGeneratedPart(page, "new\n"),
            "# Title\nprose\n" + std::string(kGeneratedMarker) + "\nnew\n");
  EXPECT_THROW(ReplaceGeneratedPart("# no marker\n", "new\n"), OptionsError);
}

}  // namespace lidarshop
