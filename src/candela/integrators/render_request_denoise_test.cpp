// plan_render with a request to denoise (RenderRequest::denoise): the sampler makes two independent
// halves, the plan says so, and what cannot be denoised is refused with the flags that ask for it.
#include <gtest/gtest.h>

#include <string>

#include "candela/integrators/render_request.h"
#include "candela/io/scene_reader.h"

namespace candela {
namespace {

SceneDesc denoise_plan_scene() { return read_json_scene(builtin_scene_json(), "<built-in>", "."); }

TEST(DenoiseRequest, ForcesTwoIndependentHalvesAndIsPlanned) {
  SceneDesc scene = denoise_plan_scene();
  ASSERT_FALSE(scene.settings.sampler.replicas);
  RenderRequest request;
  request.denoise = true;
  const RenderPlan plan = plan_render(request, scene);
  EXPECT_TRUE(plan.denoise);
  EXPECT_TRUE(scene.settings.sampler.replicas);
  // The target stays the raw image's: its budget is unchanged by denoising.
  SceneDesc targeted = denoise_plan_scene();
  request.target_error = 0.01;
  EXPECT_EQ(plan_render(request, targeted).target_error, 0.01);
  SceneDesc plain = denoise_plan_scene();
  EXPECT_FALSE(plan_render(RenderRequest{}, plain).denoise);
  EXPECT_FALSE(plain.settings.sampler.replicas);
}

TEST(DenoiseRequest, RefusesWhatItCannotDenoise) {
  struct Case {
    void (*set)(RenderRequest&);
    const char* message;
  };
  const Case cases[] = {
      {[](RenderRequest& r) { r.pixel = "1,2"; }, "--denoise cannot be combined with --pixel"},
      {[](RenderRequest& r) { r.part = "1/2"; }, "--denoise cannot be combined with --part"},
      {[](RenderRequest& r) { r.resume = "x.ckpt"; }, "--denoise cannot be combined with --resume"},
      {[](RenderRequest& r) { r.integrator = "sppm"; }, "--denoise: the sppm integrator's pixels have no two"},
  };
  for (const Case& c : cases) {
    RenderRequest request;
    request.denoise = true;
    c.set(request);
    SceneDesc scene = denoise_plan_scene();
    try {
      plan_render(request, scene);
      ADD_FAILURE() << c.message << ": accepted";
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
    // The same request without --denoise is accepted.
    request.denoise = false;
    SceneDesc again = denoise_plan_scene();
    EXPECT_NO_THROW(plan_render(request, again)) << c.message;
  }
}

}  // namespace
}  // namespace candela
