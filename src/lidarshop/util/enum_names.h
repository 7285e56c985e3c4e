// Enums to and from their names, one way everywhere (CLI values, JSON, the HTTP API, Python).
//
// A module describes an enum next to its declaration:
//
//   enum class FillMethod { kGradient, kLaplace, kDepthPatch, kTelea };
//   template <>
//   const EnumInfo& EnumInfoOf<FillMethod>();   // defined in the module's options_info.cc:
//
//   template <>
//   const EnumInfo& EnumInfoOf<FillMethod>() {
//     static const EnumInfo info = MakeEnumInfo<FillMethod>("fill method", {
//         {FillMethod::kGradient, "gradient", "gradient-domain patches + Poisson"}, ...});
//     return info;
//   }
//
// Names are lower case with '-' between words ("depth-patch"); parsing is exact and an unknown name gets the
// list of valid ones and the closest ("did you mean 'gradient'?").
#pragma once

#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace lidarshop {

struct EnumInfo {
  struct Choice {
    int value;
    std::string name;
    std::string doc;
  };
  std::string doc;  // what the enum chooses, e.g. "fill method"
  std::vector<Choice> choices;

  const std::string& Name(int value) const;  // LIDARSHOP_CHECK that the value is described
  // The value named `name`; OptionsError "'magic' is not a fill method: gradient|laplace|depth-patch|telea
  // (did you mean 'gradient'?)" otherwise.
  int Parse(std::string_view name) const;
  std::string NamesText(std::string_view separator = "|") const;  // "gradient|laplace|depth-patch|telea"
};

template <class E>
const EnumInfo& EnumInfoOf();

template <class E>
struct EnumChoice {
  E value;
  std::string name;
  std::string doc;
};

template <class E>
EnumInfo MakeEnumInfo(std::string doc, std::vector<EnumChoice<E>> choices) {
  EnumInfo info;
  info.doc = std::move(doc);
  for (auto& choice : choices) {
    info.choices.push_back({static_cast<int>(choice.value), std::move(choice.name), std::move(choice.doc)});
  }
  return info;
}

template <class E, class = std::enable_if_t<std::is_enum_v<E>>>
const std::string& ToString(E value) {
  return EnumInfoOf<E>().Name(static_cast<int>(value));
}

template <class E>
E ParseEnum(std::string_view name) {
  return static_cast<E>(EnumInfoOf<E>().Parse(name));
}

// The closest of `candidates` to `text` by edit distance, or "" when none is close (more than half of the
// text's length away). Used for every "did you mean" of the CLI, JSON keys and enum names.
std::string ClosestMatch(std::string_view text, const std::vector<std::string>& candidates);

}  // namespace lidarshop
