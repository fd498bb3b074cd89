#include "jobs/drivers/run.hpp"

#include "jobs/digest/sha256.hpp"

#include "jobs/drivers/vof_lab/run.hpp"
#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/record_head.hpp"
#include "jobs/drivers/vof_terrain/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "engine/sh2d.hpp"
#include "jobs/formats/iseesnow.hpp"
#include "jobs/formats/sh_checkpoint.hpp"
#include "jobs/formats/timeseries.hpp"
#include "jobs/figures/qml.hpp"

namespace runout::jobs {
namespace fs = std::filesystem;

namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// run.json of a depth-averaged run; continued_from: NaN for a run not continued from a checkpoint.
void write_record(const std::string& path, const ResolvedScenario& s, const terrain::DemReport& dem_rep, const terrain::Grid& grid,
                  const terrain::ReleaseReport& rel_rep, const engine::Sh2dResult& res, const RunSummary& sum, double continued_from,
                  const HazardOutputs& outputs, int frames, const std::vector<terrain::ReleaseArea>& secondary) {
  const auto& d = res.diag;
  const bool continued = !std::isnan(continued_from);
  v1::RunRecord rec = run_record_head(s, "depth-averaged");
  record_inputs(rec, dem_rep, grid, rel_rep);
  auto* gr = rec.mutable_grid();
  gr->add_local_origin(grid.x_min + 0.5 * grid.nx * grid.dx);
  gr->add_local_origin(grid.y_min + 0.5 * grid.ny * grid.dx);
  auto* mb = rec.mutable_mass_balance();
  mb->set_volume_initial_m3(d.volume_initial);
  mb->set_volume_final_m3(d.volume_final);
  mb->set_volume_outflow_m3(d.volume_outflow);
  mb->set_relative_error(d.volume_error());
  mb->set_volume_secondary_m3(d.volume_secondary);
  for (std::size_t a = 0; a < secondary.size(); ++a) {
    auto* sr = rec.mutable_release()->add_secondary();
    sr->set_name(secondary[a].name);
    sr->set_cells(int(std::count_if(secondary[a].h.begin(), secondary[a].h.end(), [](double h) { return h > 0; })));
    sr->set_volume_m3(secondary[a].volume_m3);
    if (a < d.secondary_time.size() && std::isfinite(d.secondary_time[a])) sr->set_released_at_s(d.secondary_time[a]);
  }
  auto* so = rec.mutable_solver();
  so->set_steps(int(d.steps));
  so->set_simulated_s(d.t);
  so->set_stop(sum.stop);
  if (continued) so->set_continued_from_t_s(continued_from);
  so->set_max_speed_m_s(d.max_speed);
  so->set_kinetic_energy_peak(d.kinetic_energy_peak);
  so->set_positivity_limited(double(d.positivity_limited));
  so->set_cell_updates(d.cell_updates);
  so->set_mean_active_fraction(d.mean_active_fraction);
  so->set_max_active_fraction(d.max_active_fraction);
  for (const auto& n : sum.notes)  // what the reader of the maps must know (the release's own notes stay in release.notes)
    if (std::find(rel_rep.notes.begin(), rel_rep.notes.end(), n) == rel_rep.notes.end()) rec.add_notes(n);
  auto* re = rec.mutable_results();
  record_hazard_results(s, sum, outputs, *re);
  re->set_timeseries_frames(frames);
  auto* ti = rec.mutable_timings_s();
  ti->set_prepare(sum.seconds_prepare);
  ti->set_run(sum.seconds_run);
  ti->set_write(sum.seconds_write);
  for (const auto& f : sum.files) rec.add_outputs(f);
  rec.add_outputs("run.json");
  write_run_record(path, rec);
}

// The secondary release areas as the engine takes them: the cells of each and their depths.
std::vector<engine::SecondaryRelease> engine_secondary(const std::vector<terrain::ReleaseArea>& areas) {
  std::vector<engine::SecondaryRelease> out;
  for (const auto& a : areas) {
    engine::SecondaryRelease sr{a.name, {}, {}};
    for (std::size_t k = 0; k < a.h.size(); ++k)
      if (a.h[k] > 0) {
        sr.cells.push_back(k);
        sr.depth.push_back(a.h[k]);
      }
    out.push_back(std::move(sr));
  }
  return out;
}

// The checkpoint a run continues from, checked against the scenario (its hash) and the grid.
ShCheckpoint load_restart(const RunOptions& opt, const std::string& hash, const engine::Terrain2D& t, int tile) {
  ShCheckpoint restart = read_sh_checkpoint(opt.restart_path);
  if (restart.scenario_hash != hash)
    throw ScenarioError("checkpoint " + opt.restart_path + " belongs to another scenario (its scenario hash " +
                        restart.scenario_hash.substr(0, 12) + "... is not this one's " + hash.substr(0, 12) + "...)");
  if (restart.state.nx != t.nx || restart.state.ny != t.ny || restart.state.tile != tile)
    throw ScenarioError("checkpoint " + opt.restart_path + " is of another grid");
  return restart;
}

// The grid from the terrain cache (`dir`) when it holds this DEM, area of interest and grid, else
// prepared and saved there. The key is the request and each input file's path, size and
// modification time: a file changed in place gets a new entry.
terrain::Grid cached_grid(const terrain::DemRequest& q, const std::string& dir, terrain::DemReport& rep) {
  if (dir.empty()) return terrain::prepare_grid(q, &rep);
  Sha256 h;
  h.update("runout terrain cache 1\n");
  for (const auto& f : {q.dem_path, q.aoi_path}) {
    std::error_code ec;
    const auto canon = f.empty() ? fs::path() : fs::canonical(f, ec);
    const auto size = f.empty() ? 0 : fs::file_size(f, ec);
    const auto mtime = f.empty() ? fs::file_time_type() : fs::last_write_time(f, ec);
    if (ec) return terrain::prepare_grid(q, &rep);  // the preparation names the file's problem
    h.update(canon.string() + "\n" + std::to_string(size) + "\n" + std::to_string(mtime.time_since_epoch().count()) + "\n");
  }
  char b[200];
  std::snprintf(b, sizeof b, "%.17g %.17g %.17g\n", q.resolution, q.memory_budget_bytes, q.bytes_per_cell);
  h.update(q.dem_crs + "\n" + q.target_crs + "\n" + q.resampling + "\n" + b);
  const std::string path = (fs::path(dir) / (h.hex() + ".grid")).string();
  terrain::Grid g;
  if (terrain::load_grid(path, g, rep)) return g;
  g = terrain::prepare_grid(q, &rep);
  std::error_code ec;
  fs::create_directories(dir, ec);
  terrain::save_grid(path, g, rep);
  return g;
}

}  // namespace

RunSummary run_scenario(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt) {
  if (s.terrain) return run_terrain_vof(s, out_dir, opt);
  if (s.vof) return run_lab(s, out_dir, opt);
  RunSummary sum;
  const auto t0 = std::chrono::steady_clock::now();
  terrain::DemReport dem_rep;
  const terrain::Grid grid = cached_grid(s.dem, opt.terrain_cache_dir, dem_rep);
  terrain::ReleaseReport rel_rep;
  const auto h0 = terrain::rasterize_releases(grid, s.dem, s.releases, &rel_rep);
  const auto output_inputs = read_output_inputs(s, grid, h0);  // a bad point, line or outline: refused before the run
  sum.nx = grid.nx;
  sum.ny = grid.ny;
  sum.dx = grid.dx;
  sum.crs = grid.crs_name;
  sum.release_area_m2 = rel_rep.area_m2;
  sum.release_volume_m3 = rel_rep.volume_m3;
  sum.notes = rel_rep.notes;
  const engine::Terrain2D t = engine_terrain(grid);
  auto cfg = s.config;
  const auto secondary = terrain::secondary_release_areas(grid, s.dem, s.releases);
  cfg.secondary = engine_secondary(secondary);
  cfg.time.progress = opt.progress;
  cfg.time.progress_every = opt.progress_every;
  sum.seconds_prepare = since(t0);

  // Checkpoints: the solver's whole state between two steps, with the scenario's hash; the time
  // series so far lies beside it (CHECKPOINT.timeseries.h5), so that a continued run's outputs are
  // the whole run's.
  const bool checkpoints = !opt.checkpoint_path.empty(), continued = !opt.restart_path.empty();
  const std::string hash = checkpoints || continued ? scenario_hash(s) : std::string();
  ShCheckpoint restart;
  if (continued) restart = load_restart(opt, hash, t, cfg.tile);

  std::unique_ptr<TimeSeriesWriter> series;
  if (s.timeseries_interval > 0) {
    series = continued ? std::make_unique<TimeSeriesWriter>(out_dir, grid, t, cfg.flow_threshold, opt.restart_path + ".timeseries.h5",
                                                                     restart.timeseries_frames)
                       : std::make_unique<TimeSeriesWriter>(out_dir, grid, t, cfg.flow_threshold);
    cfg.snapshot_interval = s.timeseries_interval;
    cfg.snapshot = [&](double time, const engine::Sh2dStateView& v) { series->write(time, v); };
  }
  if (checkpoints) {
    cfg.checkpoint_interval = opt.checkpoint_interval_s;
    cfg.checkpoint = [&](const engine::Sh2dCheckpoint& c) {
      // The frames first: a checkpoint never refers to frames that are not beside it.
      if (series) series->save_copy(opt.checkpoint_path + ".timeseries.h5");
      write_sh_checkpoint(opt.checkpoint_path, hash, series ? series->frames() : 0, c);
    };
  }
  const auto t1 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  const double continued_from = continued ? restart.state.t : std::numeric_limits<double>::quiet_NaN();
  engine::Sh2dResult res;
  if (continued) {
    try {
      res = engine::run_sh2d(t, cfg, restart.state);
    } catch (const std::invalid_argument& e) {  // the engine's checks of the checkpoint
      throw ScenarioError("checkpoint " + opt.restart_path + ": " + e.what());
    }
  } else {
    res = engine::run_sh2d(t, cfg, engine::state_from_normal_depth(t, h0));
  }
  restart.state = {};  // its fields are no longer needed
  sum.cpu_seconds = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  int frames = 0;
  if (series) frames = series->finish();
  sum.seconds_run = since(t1);
  const auto& d = res.diag;
  sum.volume_initial = d.volume_initial;
  sum.volume_final = d.volume_final;
  sum.volume_outflow = d.volume_outflow;
  sum.volume_error = d.volume_error();
  sum.t = d.t;
  sum.steps = d.steps;
  sum.stop = std::string(engine::to_string(d.stop));
  sum.max_speed = d.max_speed;

  hazard_figures(s, grid, h0, res.hazard, sum);
  require_finite_figures({{"final volume", d.volume_final}, {"outflow volume", d.volume_outflow}, {"maximum speed", d.max_speed},
                          {"maximum depth", sum.max_depth}, {"kinetic-energy peak", d.kinetic_energy_peak}, {"runout", sum.runout_m}});

  // Outputs.
  const auto t2 = std::chrono::steady_clock::now();
  const auto outputs = write_hazard_outputs(s, grid, h0, res.hazard, output_inputs, out_dir, sum);
  if (series) {
    // QGIS styles for the frames' GeoTIFFs: the depth and speed maps' classes, on any band chosen.
    figures::write_qml_ramp((fs::path(out_dir) / "timeseries_depth.qml").string(), figures::hazard_palette("max_depth"));
    figures::write_qml_ramp((fs::path(out_dir) / "timeseries_speed.qml").string(), figures::hazard_palette("max_speed"));
    for (const char* f : {"timeseries.h5", "timeseries.xmf", "timeseries_depth.tif", "timeseries_depth.qml", "timeseries_speed.tif",
                          "timeseries_speed.qml"})
      sum.files.push_back(f);
  }
  sum.seconds_write = since(t2);

  const std::string record = (fs::path(out_dir) / "run.json").string();
  if (!opt.iseesnow_id.empty())
    for (auto& f : write_iseesnow(s, opt.iseesnow_id, out_dir, grid, res, sum.cpu_seconds)) sum.files.push_back(std::move(f));
  write_record(record, s, dem_rep, grid, rel_rep, res, sum, continued_from, outputs, frames, secondary);
  sum.files.push_back("run.json");
  return sum;
}

}  // namespace runout::jobs
