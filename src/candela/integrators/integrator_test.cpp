// The integrator registry: names, the selective settings each reads, and what render() refuses.
#include "candela/integrators/integrator.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string_view>
#include <vector>

#include "candela/base/error.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using Keys = std::vector<std::string_view>;

TEST(IntegratorRegistry, NamesComeFromTheTable) {
  EXPECT_EQ(integrator_names(), "path, bdpt, mlt, volpath, ambient_occlusion, light_path, sppm");
  EXPECT_EQ(integrator_names(/*and_choosers=*/true),
            "path, bdpt, mlt, volpath, ambient_occlusion, light_path, sppm, auto");
  EXPECT_EQ(integrators_with(&IntegratorTraits::strategy_images), "bdpt");
  for (const IntegratorEntry& entry : integrators()) {
    EXPECT_EQ(find_integrator(entry.name), &entry);
    for (std::string_view key : entry.reads) {
      bool known = false;
      for (const SelectiveSetting& s : kSelectiveSettings) known = known || s.key == key;
      EXPECT_TRUE(known) << entry.name << " reads " << key << ", which kSelectiveSettings does not list";
    }
  }
  EXPECT_EQ(find_integrator("whitted"), nullptr);
  EXPECT_EQ(find_integrator_traits("whitted"), nullptr);
}

// The registry binds every entry of the traits table (description/integrator_traits.h), in its
// order, to what runs it, as its traits say: a render function, or the candidates and the choice of
// the one that chooses; the strategy images' maker exactly where the traits say it writes them.
TEST(IntegratorRegistry, EveryTraitsEntryIsBoundAsItsTraitsSay) {
  ASSERT_EQ(integrators().size(), integrator_traits().size());
  for (size_t i = 0; i < integrators().size(); ++i) {
    const IntegratorEntry& entry = integrators()[i];
    const IntegratorTraits& traits = integrator_traits()[i];
    EXPECT_EQ(entry.name, traits.name);
    EXPECT_EQ(find_integrator_traits(entry.name), &traits);
    EXPECT_EQ(entry.reads, traits.reads) << entry.name;
    EXPECT_EQ(entry.render != nullptr, !traits.chooses) << entry.name;
    EXPECT_EQ(entry.choose != nullptr, traits.chooses) << entry.name;
    EXPECT_EQ(entry.candidates != nullptr, traits.chooses) << entry.name;
    EXPECT_EQ(entry.make_strategy_images != nullptr, traits.strategy_images) << entry.name;
  }
  const IntegratorEntry* chooser = find_integrator("auto");
  ASSERT_NE(chooser, nullptr);
  EXPECT_TRUE(chooser->chooses);
  // It may read what one of the others reads, and reads nothing itself.
  EXPECT_TRUE(may_read_setting(*chooser, "mlt"));
  EXPECT_TRUE(may_read_setting(*chooser, "mis"));
  EXPECT_FALSE(may_read_setting(*find_integrator("bdpt"), "mis"));
}

TEST(IntegratorRegistry, SetButUnreadListsWhatDiffersFromTheDefaultsAndTheIntegratorIgnores) {
  RenderSettings settings;
  for (const IntegratorEntry& entry : integrators()) EXPECT_TRUE(set_but_unread(entry, settings).empty()) << entry.name;
  settings.path.mis = false;
  settings.light_selection = LightSelection::Paper;
  settings.mlt.chains = 5;
  settings.adaptive_spp = 32;
  EXPECT_EQ(set_but_unread(*find_integrator("path"), settings), (Keys{"mlt"}));
  EXPECT_EQ(set_but_unread(*find_integrator("bdpt"), settings), (Keys{"mis", "light_selection=paper", "mlt"}));
  EXPECT_EQ(set_but_unread(*find_integrator("mlt"), settings), (Keys{"mis", "light_selection=paper", "adaptive"}));
  EXPECT_EQ(unread_setting_message(*find_integrator("mlt"), "adaptive"),
            "the mlt integrator does not read adaptive (adaptive sampling; read by: path, bdpt, volpath, "
            "ambient_occlusion)");
}

TEST(IntegratorRegistry, RenderRefusesWhatTheIntegratorCannotDo) {
  SceneDesc d = testing::closed_diffuse_sphere(0.5f, 2);
  const Scene scene(d);
  RenderOptions options;
  options.progress = false;
  RenderSettings settings = d.settings;
  settings.integrator = "whitted";
  Film film(d.film.width, d.film.height);
  EXPECT_THROW(render(scene, settings, film, options), UsageError);
  settings.integrator = "mlt";
  settings.adaptive_threshold = 0.1f;
  EXPECT_THROW(render(scene, settings, film, options), UsageError);
  settings.adaptive_threshold = 0;
  options.only_x = options.only_y = 1;
  EXPECT_THROW(render(scene, settings, film, options), UsageError);
  // A film with samples: path continues it, mlt cannot.
  options.only_x = options.only_y = -1;
  settings.integrator = "path";
  settings.spp = 1;
  render(scene, settings, film, options);
  settings.integrator = "mlt";
  EXPECT_THROW(render(scene, settings, film, options), UsageError);
  // The one that chooses renders through render_requested, which runs its choice.
  settings.integrator = "auto";
  Film empty(d.film.width, d.film.height);
  EXPECT_THROW(render(scene, settings, empty, options), UsageError);
}

// check_capabilities names the flag that asks and the integrator that cannot.
TEST(IntegratorRegistry, CapabilityChecksNameTheFlagAndTheIntegrator) {
  auto message = [](std::string_view name, const CapabilityNeeds& needs) {
    try {
      check_capabilities(*find_integrator_traits(name), needs);
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message("mlt", {.continues_film = true}),
            "--checkpoint and --resume are not supported with the mlt integrator (it cannot continue a partly "
            "rendered film)");
  EXPECT_EQ(message("mlt", {.one_pixel = true}),
            "--pixel cannot be used with the mlt integrator (it cannot render one pixel alone)");
  EXPECT_EQ(message("mlt", {.part = true}),
            "--part: the mlt integrator does not render tile by tile (path, bdpt, volpath, "
            "ambient_occlusion, light_path do)");
  EXPECT_EQ(message("path", {.strategy_images = true}),
            "--bdpt-strategies: the path integrator writes no strategy images (bdpt does)");
  EXPECT_EQ(message("mlt", {.adaptive = true}), "adaptive sampling does not apply to the mlt integrator");
  EXPECT_EQ(message("sppm", {.target_error = true}),
            "--target-error: the sppm integrator gives no error estimate (its pixels have no two independent halves)");
  EXPECT_EQ(message("path", {.media = true}),
            "the scene has participating media, which the path integrator does not render: use --integrator volpath");
  EXPECT_EQ(message("auto", {.part = true}),
            "--integrator auto cannot be combined with --checkpoint, --resume, --pixel or --part (name the "
            "integrator)");
  EXPECT_EQ(message("auto", {.strategy_images = true}), "--bdpt-strategies needs --integrator bdpt, not auto");
  EXPECT_EQ(message("bdpt", {.continues_film = true, .one_pixel = true, .part = true, .strategy_images = true,
                             .adaptive = true, .media = true}),
            "");
}

}  // namespace
}  // namespace candela
