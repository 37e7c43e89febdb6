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
  EXPECT_EQ(integrator_names(), "path, bdpt, mlt, volpath");
  for (const IntegratorEntry& entry : integrators()) {
    EXPECT_EQ(find_integrator(entry.name), &entry);
    EXPECT_NE(entry.render, nullptr) << entry.name;
    for (std::string_view key : entry.reads) {
      bool known = false;
      for (const SelectiveSetting& s : kSelectiveSettings) known = known || s.key == key;
      EXPECT_TRUE(known) << entry.name << " reads " << key << ", which kSelectiveSettings does not list";
    }
  }
  EXPECT_EQ(find_integrator("whitted"), nullptr);
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
            "the mlt integrator does not read adaptive (adaptive sampling; read by: path, bdpt, volpath)");
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
}

}  // namespace
}  // namespace candela
