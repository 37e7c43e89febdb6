#include "candela/io/parameter_usage.h"

#include <gtest/gtest.h>

namespace candela {
namespace {

TEST(ParameterUsage, TheFirstParameterNothingAskedForIsReportedWithItsPlace) {
  ParameterUsage usage;
  usage.give("radius", {"a.pbrt", 3, 5, ""});
  usage.give("raduis", {"a.pbrt", 4, 7, ""});
  usage.give("center", {"a.pbrt", 5, 1, ""});
  EXPECT_TRUE(usage.ask("radius"));
  EXPECT_FALSE(usage.ask("zmin"));
  const ParameterUsage::Parameter* unused = usage.first_unused();
  ASSERT_NE(unused, nullptr);
  EXPECT_EQ(unused->name, "raduis");
  EXPECT_EQ(unused->where.to_string(), "a.pbrt:4:7");
  EXPECT_EQ(usage.asked_list(), "radius, zmin");
  usage.ask("raduis");
  usage.mark_used("center");
  EXPECT_EQ(usage.first_unused(), nullptr);
  EXPECT_EQ(usage.asked_list(), "radius, zmin, raduis");  // mark_used is not a read
}

TEST(ParameterUsage, AskingForARepeatedNameUsesEveryCopy) {
  ParameterUsage usage;
  usage.give("p", {});
  usage.give("p", {});
  EXPECT_TRUE(usage.was_given("p"));
  EXPECT_FALSE(usage.was_given("q"));
  usage.ask("p");
  EXPECT_EQ(usage.first_unused(), nullptr);
}

}  // namespace
}  // namespace candela
