#pragma once
// What a scene reader made of a texture against what it should be, field by field: shared by the
// JSON and pbrt reader tests.
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "candela/description/scene_desc.h"

namespace candela::testing {

inline void expect_mapping(const UVMapping& actual, const UVMapping& expected, const std::string& what) {
  for (auto [field, name] : {std::pair{&UVMapping::su, "su"}, {&UVMapping::sv, "sv"}, {&UVMapping::du, "du"},
                              {&UVMapping::dv, "dv"}, {&UVMapping::s_from_v, "s_from_v"}, {&UVMapping::t_from_u, "t_from_u"}})
    EXPECT_FLOAT_EQ(actual.*field, expected.*field) << what << ", " << name;
}

// Every setting but the file name (which each reader resolves in its own way).
inline void expect_image_settings(const ImageTexture& actual, const ImageTexture& expected, const std::string& what) {
  EXPECT_EQ(actual.wrap, expected.wrap) << what;
  EXPECT_EQ(actual.encoding, expected.encoding) << what;
  EXPECT_EQ(actual.filter, expected.filter) << what;
  EXPECT_FLOAT_EQ(actual.scale, expected.scale) << what;
  EXPECT_EQ(actual.invert, expected.invert) << what;
  EXPECT_EQ(actual.luminance, expected.luminance) << what;
  expect_mapping(actual.mapping, expected.mapping, what);
}

}  // namespace candela::testing
