// The option table (description/render_options.h) walked through every front end it generates: an option
// added to the table must appear in the command line's --help, be checked, applied, refused where the
// integrator does not read it, and enter the fingerprint, with no other edit. (The Python module's
// keywords are checked against the table in python/tests/test_options.py.)
#include "candela/description/render_options.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <set>

#include "candela/integrators/integrator.h"
#include "candela/integrators/render_request.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/command_line.h"

namespace candela {
namespace {

using testing::run_command;

SceneDesc builtin_scene() { return read_json_scene(builtin_scene_json(), "<built-in>", "."); }

// Requests giving `option` each of a few valid values: every choice, a range's two ends (as text,
// for messages, in `shown`).
std::vector<RenderRequest> with_valid_values(const RenderOption& option, std::vector<std::string>& shown) {
  std::vector<RenderRequest> requests;
  auto add = [&](auto assign, std::string text) {
    RenderRequest request;
    std::visit([&](auto member) { assign(request.*member); }, option.field);
    requests.push_back(request);
    shown.push_back(std::move(text));
  };
  std::visit(
      [&](auto member) {
        using T = std::remove_cvref_t<decltype(RenderRequest{}.*member)>;
        auto set = [&](T value, std::string text) {
          add([value](auto& field) {
                if constexpr (std::is_same_v<std::remove_cvref_t<decltype(field)>, T>) field = value;
              },
              std::move(text));
        };
        if constexpr (std::is_same_v<T, bool>) {
          set(true, "(flag)");
        } else if constexpr (std::is_same_v<T, std::string>) {
          if (const auto* choice = std::get_if<ChoiceValue>(&option.rule))
            for (const std::string& name : choice->names) set(name, name);
          else if (option.name == "resolution") set("17x9", "17x9");
          else if (option.name == "time_limit") set("2m", "2m");
          else if (option.name == "integrator") set("bdpt", "bdpt");
          else set("/tmp", "/tmp");
        } else {
          using V = typename T::value_type;
          std::vector<double> values = {7};
          if (const auto* range = std::get_if<ValueRange>(&option.rule)) values = {range->lo + 1.0 / 64, range->hi};
          for (double x : values) {
            V v = std::is_integral_v<V> ? V(std::ceil(x)) : V(x);
            set(T(v), std::to_string(v));
          }
        }
      },
      option.field);
  return requests;
}

// A request that lets `option` matter: the integrator that reads it, and adaptive sampling on for
// the adaptive options that only tune it.
RenderRequest enabling(const RenderOption& option) {
  RenderRequest request;
  for (const IntegratorEntry& entry : integrators())
    if (!option.reads.empty() && entry.reads_setting(option.reads)) {
      request.integrator = std::string(entry.name);
      break;
    }
  if (option.reads == "adaptive") {
    if (option.name == "adaptive_threshold") request.adaptive_spp = 64;
    else request.adaptive_threshold = 0.5f;
  }
  return request;
}

// `base` with what `extra` gives for `option`.
RenderRequest combined(const RenderOption& option, RenderRequest base, const RenderRequest& extra) {
  std::visit([&](auto member) { base.*member = extra.*member; }, option.field);
  return base;
}

TEST(RenderOptionTable, NamesAreUniqueAndFlagsFollowThem) {
  std::set<std::string> names;
  for (const RenderOption& option : render_options()) {
    EXPECT_TRUE(names.insert(option.name).second) << option.name;
    EXPECT_EQ(option.flag().substr(0, 2), "--");
    EXPECT_EQ(option.flag().find('_'), std::string::npos) << option.flag();
    EXPECT_FALSE(option.help.empty()) << option.name;
    EXPECT_EQ(find_render_option(option.name), &option);
    EXPECT_EQ(option.fingerprint == nullptr, option.fingerprint_key.empty()) << option.name;
  }
}

TEST(RenderOptionTable, EverySelectiveOptionNamesAKnownSetting) {
  for (const RenderOption& option : render_options()) {
    if (option.reads.empty()) continue;
    bool known = false;
    for (const SelectiveSetting& s : kSelectiveSettings) known = known || s.key == option.reads;
    EXPECT_TRUE(known) << option.name << " reads " << option.reads;
  }
}

TEST(RenderOptionTable, EveryOptionIsInTheCommandLinesHelp) {
  const testing::CommandResult help = run_command(std::string(CANDELA_CLI_PATH) + " render --help");
  ASSERT_EQ(help.exit_code, 0) << help.output;
  for (const RenderOption& option : render_options())
    EXPECT_NE(help.output.find(option.flag()), std::string::npos) << option.flag() << " is missing from --help";
}

TEST(RenderOptionTable, EveryValueOutsideItsRuleIsRefusedNamingTheFlag) {
  for (const RenderOption& option : render_options()) {
    RenderRequest request;
    bool has_bad_value = std::visit(
        [&](auto member) {
          auto& value = request.*member;
          using T = std::remove_cvref_t<decltype(value)>;
          if constexpr (std::is_same_v<T, bool>) {
            return false;
          } else if constexpr (std::is_same_v<T, std::string>) {
            value = "no-such-value";
            return !std::holds_alternative<AnyValue>(option.rule);
          } else {
            using V = typename T::value_type;
            if (const auto* range = std::get_if<ValueRange>(&option.rule)) {
              if (range->lo <= double(std::numeric_limits<V>::lowest())) return false;
              value = V(range->lo - 1);
              if (double(*value) >= range->lo) value = V(range->lo / 2);  // a float range starting above 0
              return double(*value) < range->lo;
            }
            if (std::holds_alternative<PositiveValue>(option.rule)) {
              value = V(0);
              return true;
            }
            return false;
          }
        },
        option.field);
    if (!has_bad_value) continue;
    try {
      check_request_values(request);
      ADD_FAILURE() << option.flag() << ": a value outside its rule was accepted";
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find(option.flag()), std::string::npos) << e.what();
    }
  }
}

TEST(RenderOptionTable, EveryAppliedOptionChangesTheSceneOrItsFingerprint) {
  const SceneDesc scene = builtin_scene();
  for (const RenderOption& option : render_options()) {
    if (!option.apply && !option.fingerprint) continue;
    const RenderRequest base = enabling(option);
    SceneDesc before = scene;
    ASSERT_NO_THROW(plan_render(base, before)) << option.flag();
    std::vector<std::string> shown;
    bool scene_changed = false, fingerprint_changed = false;
    const std::vector<RenderRequest> requests = with_valid_values(option, shown);
    int applied = 0;
    for (size_t i = 0; i < requests.size(); ++i) {
      const RenderRequest request = combined(option, base, requests[i]);
      SceneDesc after = scene;
      try {
        plan_render(request, after);
      } catch (const UsageError&) {
        continue;  // a rule across options (the MLT probabilities' sum), not this option's own
      }
      ++applied;
      scene_changed = scene_changed || scene_to_json(after) != scene_to_json(before);
      fingerprint_changed = fingerprint_changed || !render_fingerprint("", before, base)
                                                         .difference(render_fingerprint("", after, request))
                                                         .empty();
    }
    EXPECT_GT(applied, 0) << option.flag() << ": no valid value was accepted";
    EXPECT_TRUE(scene_changed || !option.apply) << option.flag() << ": no value changed the scene";
    EXPECT_TRUE(fingerprint_changed || !option.fingerprint) << option.flag() << ": no value changed the fingerprint";
  }
}

TEST(RenderOptionTable, SelectiveOptionsAreRefusedByIntegratorsThatDoNotReadThem) {
  for (const RenderOption& option : render_options()) {
    if (option.reads.empty()) continue;
    for (const IntegratorEntry& entry : integrators()) {
      // (One that chooses reads what its candidates read: auto_candidates.)
      if (entry.chooses || entry.reads_setting(option.reads)) continue;
      std::vector<std::string> shown;
      bool named = false;
      for (RenderRequest request : with_valid_values(option, shown)) {
        if (!option.reads_when.empty())
          request.*std::get<std::string RenderRequest::*>(option.field) = std::string(option.reads_when);
        request.integrator = std::string(entry.name);
        SceneDesc scene = builtin_scene();
        try {
          plan_render(request, scene);
          ADD_FAILURE() << option.flag() << " was accepted by " << entry.name << ", which does not read it";
        } catch (const UsageError& e) {
          // Another rule (a batch larger than the budget) may speak first for some values.
          named = named || std::string(e.what()).find(option.flag_for_messages() + ": the " +
                                                      std::string(entry.name)) != std::string::npos;
        }
      }
      EXPECT_TRUE(named) << option.flag() << " with " << entry.name << ": no refusal named both";
    }
  }
}

// The scene file's "render" keys are generated from the table too: each option with a scene key is
// written by the JSON writer and read back by the JSON reader to the same value, under its key.
TEST(RenderOptionTable, EveryOptionWithASceneKeyRoundTripsThroughTheSceneFile) {
  const SceneDesc scene = builtin_scene();
  for (const RenderOption& option : render_options()) {
    EXPECT_EQ(option.scene_key.empty(), option.extract == nullptr) << option.name;
    if (option.scene_key.empty()) continue;
    EXPECT_NE(option.apply, nullptr) << option.name;
    std::vector<std::string> shown;
    const std::vector<RenderRequest> requests = with_valid_values(option, shown);
    int written = 0;
    for (size_t i = 0; i < requests.size(); ++i) {
      SceneDesc given = scene;
      try {
        plan_render(combined(option, enabling(option), requests[i]), given);
      } catch (const UsageError&) {
        continue;  // a rule across options
      }
      const std::string text = scene_to_json(given);
      const SceneDesc read = read_json_scene(text, "<written>", ".");
      RenderRequest before, after;
      option.extract(given, before);
      option.extract(read, after);
      std::visit([&](auto member) { EXPECT_EQ(before.*member, after.*member) << option.scene_key << " " << shown[i]; },
                 option.field);
      // Written under its key where the scene gives it (an unset flag is the file's default).
      nlohmann::json value = nlohmann::json::parse(text)["render"];
      const std::string key(option.scene_key);
      const size_t dot = key.find('.');
      if (dot != std::string::npos) value = value.value(key.substr(0, dot), nlohmann::json::object());
      if (option.given(before)) {
        EXPECT_TRUE(value.contains(key.substr(dot + 1))) << key << " " << shown[i] << " is not written";
        ++written;
      }
    }
    EXPECT_GT(written, 0) << option.scene_key << ": no value was written";
  }
}

}  // namespace
}  // namespace candela
