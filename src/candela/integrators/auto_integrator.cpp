#include "candela/integrators/auto_integrator.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/integrators/mlt.h"
#include "candela/integrators/volpath.h"
#include "candela/render/cluster.h"

namespace candela {

std::vector<const IntegratorEntry*> auto_candidates(const RenderSettings& settings, bool has_media) {
  std::vector<const IntegratorEntry*> candidates;
  // With media only the integrators that render them apply; without, volpath is the path tracer
  // with one shadow ray and adds nothing to compare. Ambient occlusion and the light tracer render
  // another image; photon mapping's film has no error estimate for the pilots to compare.
  for (const IntegratorEntry& entry : integrators()) {
    if (entry.chooses || entry.geometric || entry.partial_transport || entry.progressive || (has_media ? !entry.participating_media : entry.render == render_volpath)) continue;
    if (set_but_unread(entry, settings).empty()) candidates.push_back(&entry);
  }
  return candidates;
}

std::string AutoChoice::summary() const {
  std::string s;
  for (const PilotRun& p : pilots) {
    s += fmt::format("{}{}: ", s.empty() ? "" : "; ", p.integrator->name);
    if (!p.error.valid) {
      s += "no estimate (" + p.error.why_not + ")";
      continue;
    }
    s += fmt::format("relMSE {:.3g} in {:.2f} s", p.error.relmse, p.seconds);
    if (budget_seconds > 0)
      s += fmt::format(", predicts {:.3g} in {:.1f} s", p.predicted, budget_seconds);
    else
      s += fmt::format(", predicts the target in {:.1f} s", p.predicted);
  }
  return s + fmt::format("; chose {} (pilots {:.2f} s{})", integrator->name, pilot_seconds,
                         budget_seconds > 0 ? fmt::format(", {:.0f}% of the budget", 100 * pilot_seconds / budget_seconds)
                                            : std::string());
}

AutoChoice choose_integrator(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options,
                             int budget_spp) {
  if (!settings.sampler.replicas) throw InternalError("choose_integrator: the pilots need the sampler's replicas");
  Cluster& cluster = options.cluster ? *options.cluster : local_cluster();
  AutoChoice choice;
  const std::vector<const IntegratorEntry*> candidates = auto_candidates(settings, scene.has_media());
  if (candidates.empty()) throw UsageError("--integrator auto: no integrator reads every setting the scene sets");
  const double time_limit = options.time_limit_seconds;
  const double slice = time_limit > 0 ? 0.1 * time_limit / double(candidates.size()) : kPilotSeconds;

  std::vector<Film> pilot_films;
  for (const IntegratorEntry* entry : candidates) {
    RenderSettings pilot_settings = settings;
    pilot_settings.integrator = std::string(entry->name);
    // MLT's bootstrap (in proportion to mlt.bootstrap) would take the whole slice and more on a deep
    // scene: its pilot bootstraps with a hundredth (at least 1000), and its depth-0 pass (spp / 16
    // samples per pixel, 16 to 256) takes 16; both times are scaled back up for the prediction.
    double bootstrap_scale = 1, direct_scale = 1;
    const bool mlt = entry->reads_setting("mlt");
    if (mlt) {
      pilot_settings.mlt.bootstrap = std::min(settings.mlt.bootstrap, std::max(1000, settings.mlt.bootstrap / 100));
      bootstrap_scale = double(settings.mlt.bootstrap) / double(pilot_settings.mlt.bootstrap);
      pilot_settings.spp = std::min(settings.spp, 256);
      direct_scale = double(mlt_direct_spp(settings.spp)) / double(mlt_direct_spp(pilot_settings.spp));
    }
    RenderOptions pilot = options;
    pilot.progress = false;
    pilot.after_pass = nullptr;
    pilot.live = nullptr;  // viewers and AOVs describe the image, not the pilots
    pilot.aovs = nullptr;
    pilot.target_error = 0;
    pilot.time_limit_seconds = slice;
    // Path and bdpt render every k-th tile in their pilot (tiles strided over the whole image, as a
    // job-array part): a pass then costs a k-th, so the pilot fits its slice with several passes, and
    // the winner continues it (each pixel from its own count) into the one image.
    double image_share = 1;
    if (entry->resumable) {
      const int tiles = ((film.width() + 15) / 16) * ((film.height() + 15) / 16);
      pilot.part_count = std::clamp(tiles / 16, 1, kPilotTileStride);
      pilot.part_index = 0;
      image_share = double((tiles + pilot.part_count - 1) / pilot.part_count) / double(tiles);
    }
    Film pilot_film(film.width(), film.height());
    // (Each candidate can render the scene as asked: auto_candidates.)
    RenderStats stats = render_with(*entry, scene, pilot_settings, pilot_film, pilot);
    PilotRun run;
    run.integrator = entry;
    // The root's clock, so every rank decides alike (the films, and so the estimates, are the same).
    run.seconds = cluster.from_root(stats.seconds);
    run.setup_seconds = cluster.from_root(stats.setup_seconds);
    run.image_share = image_share;
    // MLT's set-up in the real render: its depth-0 pass and bootstrap scaled up; its normalisation
    // (a ninth of a time limit, else in proportion to the mutations, part of the work) is priced
    // below, once the remaining budget is known.
    if (mlt) {
      // The real depth-0 pass: its samples at the pilot's pace, but under a time limit at most its
      // share of it (and at least the pilot's one pass).
      const MltStats& mlt_details = *mlt_stats(stats);
      const double direct = cluster.from_root(mlt_details.direct_seconds);
      double full_direct = direct * direct_scale;
      if (time_limit > 0) full_direct = std::min(full_direct, std::max(direct, time_limit * kMltDirectTimeShare));
      run.full_setup_seconds = full_direct + cluster.from_root(mlt_details.bootstrap_seconds) * bootstrap_scale;
    } else {
      run.full_setup_seconds = run.setup_seconds;
    }
    run.error = estimate_error(pilot_film, stats.splat_scale_relative_error);
    choice.pilot_seconds += run.seconds;
    choice.pilots.push_back(run);
    pilot_films.push_back(std::move(pilot_film));
    if (stats.cancelled) break;
  }

  // The budget in seconds: the time limit, or the path tracer's time for the spp (from its pilot's
  // pace); none with an error target.
  if (time_limit > 0) {
    choice.budget_seconds = time_limit;
  } else if (options.target_error <= 0) {
    for (size_t i = 0; i < choice.pilots.size(); ++i)
      if (choice.pilots[i].integrator->name == "path" && pilot_films[i].total_samples() > 0)
        choice.budget_seconds = choice.pilots[i].seconds * double(budget_spp) /
                                (double(pilot_films[i].total_samples()) / (double(film.width()) * film.height()));
    if (choice.budget_seconds <= 0) choice.budget_seconds = double(candidates.size()) * slice / 0.1;
  }
  const double remaining = std::max(0.0, choice.budget_seconds - choice.pilot_seconds);
  double best = std::numeric_limits<double>::infinity();
  size_t winner = 0;
  for (size_t i = 0; i < choice.pilots.size(); ++i) {
    PilotRun& p = choice.pilots[i];
    if (!p.error.valid) {
      p.predicted = std::numeric_limits<double>::infinity();
      continue;
    }
    // The pilot's own rendering time (set-up aside), the work behind its error; a pilot of every
    // k-th tile did a k-th of the work of the whole image at its samples per pixel (its pixels stay
    // ahead by them when it is continued).
    const double work = std::max(p.seconds - p.setup_seconds, 1e-6);
    const double whole_image_work = work / p.image_share;
    // BDPT's light paths splat over the whole image, but a pilot of a k-th of the tiles traces a
    // k-th of them: their part of the pilot's error is already the whole image's at its work.
    const double splat_part = std::min(p.error.splat_relmse, p.error.relmse);
    const double error = p.error.relmse - splat_part + splat_part * p.image_share;
    if (options.target_error > 0) {
      // Seconds from now to the target: a continued pilot adds to its work, a restart redoes the set-up.
      const double needed = whole_image_work * error / options.target_error;
      p.predicted = p.integrator->resumable ? std::max(0.0, needed - work) : p.full_setup_seconds + needed;
    } else if (p.integrator->resumable) {
      p.predicted = error * whole_image_work / (work + remaining);
    } else {
      // A restart: the set-up again, and a ninth of what is left normalises MLT's chains.
      const double setup = p.full_setup_seconds + (time_limit > 0 && p.integrator->reads_setting("mlt") ? remaining / 9 : 0);
      p.predicted = p.error.relmse * work / std::max(remaining - setup, 1e-6);
    }
    if (p.predicted < best) {
      best = p.predicted;
      winner = i;
    }
  }
  choice.integrator = choice.pilots[winner].integrator;
  choice.continues_pilot = choice.integrator->resumable;
  film = choice.continues_pilot ? std::move(pilot_films[winner]) : Film(film.width(), film.height());
  return choice;
}

}  // namespace candela
