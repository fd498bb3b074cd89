// The depth-averaged engine on the DEM as a run set-up (jobs/drivers/engine_run.hpp): grid,
// releases, the engine, its time series and checkpoints; hazard outputs and run.json at the end.
#include "jobs/digest/sha256.hpp"
#include "jobs/drivers/engine_run.hpp"
#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/nest/boundary.hpp"
#include "jobs/drivers/nest/run.hpp"
#include "jobs/drivers/record_head.hpp"
#include "jobs/drivers/report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "engine/sh2d.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/formats/iseesnow.hpp"
#include "jobs/formats/sh_checkpoint.hpp"
#include "jobs/formats/timeseries.hpp"
#include "jobs/figures/qml.hpp"

namespace runout::jobs {
namespace fs = std::filesystem;

namespace {

// run.json of a depth-averaged run; continued_from: NaN for a run not continued from a checkpoint.
// The nest's figures into run.json.
void record_nest(const NestSummary& n, v1::RunRecord& rec) {
  auto* r = rec.mutable_nest();
  r->set_cells(n.cells);
  r->set_boundary_faces(n.boundary_faces);
  r->set_mesh_cells(int(n.mesh_cells));
  r->set_column_width_m(n.column_width_m);
  r->set_first_layer_m(n.first_layer_m);
  r->set_band_height_m(n.band_height_m);
  r->set_inflow_depth_averaged_m3(n.inflow_depth_averaged_m3);
  r->set_inflow_3d_m3(n.inflow_3d_m3);
  r->set_inflow_relative_difference(n.inflow_depth_averaged_m3 > 0 ? std::abs(n.inflow_3d_m3 - n.inflow_depth_averaged_m3) / n.inflow_depth_averaged_m3 : 0.0);
  r->set_volume_error_3d(n.volume_error_3d);
  r->set_seconds_3d(n.seconds_3d);
  r->set_recorded_steps(int(n.recorded_steps));
  r->set_start_time_s(n.start_time_s);
  r->set_maps("inside the nest's cells the 3D run's (nest/), outside the depth-averaged run's");
  for (const auto& q : n.structures) record_structure(q, r->add_structures());
  if (!std::isnan(n.continued_from)) r->set_continued_from_s(n.continued_from);
}

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
  mb->set_volume_detrained_m3(d.volume_detrained);
  mb->set_volume_entrained_m3(d.volume_entrained);
  record_structures(sum, rec);
  if (sum.nest) record_nest(*sum.nest, rec);
  for (const auto& q : sum.dams) {
    auto* dr = rec.add_dams();
    dr->set_name(q.name);
    dr->set_kind(q.lines ? "crest lines" : "footprints");
    dr->set_cells(int(q.cells));
    dr->set_height_max_m(q.height_max_m);
    dr->set_crest_length_m(q.crest_length_m);
    dr->set_crossed_right_m3(q.crossed_right_m3);
    dr->set_crossed_left_m3(q.crossed_left_m3);
    dr->set_overflow_m3(q.overflow_m3);
    dr->set_max_depth_m(q.max_depth_m);
  }
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
  for (const auto& line : outputs.parameters) rec.add_parameters(line);
  re->set_timeseries_frames(frames);
  auto* ti = rec.mutable_timings_s();
  ti->set_prepare(sum.seconds_prepare);
  ti->set_run(sum.seconds_run);
  ti->set_write(sum.seconds_write);
  for (const auto& f : sum.files) rec.add_outputs(f);
  rec.add_outputs("run.json");
  write_run_record(path, rec);
}

// The resistance areas as the engine takes them: the scenario's band and switch, and per cell the
// drag coefficient and detrainment K of the areas whose polygons hold the cell's centre (`cells`,
// one mask per area, read_output_inputs; the largest where areas overlap; 0 elsewhere and outside
// the domain). No areas: none.
engine::ResistanceAreas resistance_areas(const ResolvedScenario& s, const std::vector<std::vector<std::uint8_t>>& cells) {
  engine::ResistanceAreas r = s.config.resistance;
  if (s.resistance.empty()) return r;
  r.c.assign(cells.front().size(), 0.0);
  r.k_det.assign(cells.front().size(), 0.0);
  for (std::size_t a = 0; a < s.resistance.size(); ++a)
    for (std::size_t k = 0; k < cells[a].size(); ++k)
      if (cells[a][k]) {
        r.c[k] = std::max(r.c[k], s.resistance[a].c);
        r.k_det[k] = std::max(r.k_det[k], s.resistance[a].k_det);
      }
  return r;
}

// The erodible cover as the engine takes it: the scenario's law and erosion energy, and per cell the
// thickest area's thickness and density (`depth`, one field per area, read_output_inputs). None: none.
engine::ErodibleCover erodible_cover(const ResolvedScenario& s, const std::vector<std::vector<double>>& depth) {
  engine::ErodibleCover e = s.config.cover;
  if (s.cover.empty()) return e;
  e.depth.assign(depth.front().size(), 0.0);
  e.density.assign(depth.front().size(), s.cover.front().density);
  for (std::size_t a = 0; a < s.cover.size(); ++a)
    for (std::size_t k = 0; k < depth[a].size(); ++k)
      if (depth[a][k] > e.depth[k]) {
        e.depth[k] = depth[a][k];
        e.density[k] = s.cover[a].density;
      }
  return e;
}

// The dams and structures as the engine sees them: each cell's wall height (the largest where dams or
// structures overlap; a structure is a footprint dam of its height) and a flux gauge across each
// dam's crest lines (a cell on the crests of two dams, where they meet, counts for the first).
void place_dams(const ResolvedScenario& s, const std::vector<terrain::DamCells>& dams, const std::vector<terrain::DamCells>& structures,
                const engine::Terrain2D& t, engine::Sh2dConfig& cfg) {
  if (dams.empty() && structures.empty()) return;
  cfg.dam_height.assign(t.cells(), 0.0);
  for (const auto& d : structures)  // walls of their height on every cell they touch
    for (std::size_t k = 0; k < d.height.size(); ++k) cfg.dam_height[k] = std::max(cfg.dam_height[k], d.height[k]);
  for (const auto& d : dams)
    for (std::size_t k = 0; k < d.height.size(); ++k) cfg.dam_height[k] = std::max(cfg.dam_height[k], d.height[k]);
  std::vector<std::uint8_t> taken(t.cells(), 0);
  for (std::size_t a = 0; a < dams.size(); ++a) {
    if (!dams[a].lines) continue;
    engine::FluxGauge g{s.dams[a].name, {}, {}};
    for (std::size_t q = 0; q < dams[a].crest.size(); ++q)
      if (!taken[dams[a].crest[q]]++) {
        g.cells.push_back(dams[a].crest[q]);
        g.sides.push_back(dams[a].sides[q]);
      }
    cfg.gauges.push_back(std::move(g));
  }
}

// What each dam held back or let pass: its gauge's crossings (crest lines) and the deepest flow on it.
std::vector<DamSummary> dam_summaries(const ResolvedScenario& s, const std::vector<terrain::DamCells>& dams,
                                      const engine::Sh2dResult& res) {
  std::vector<DamSummary> out;
  std::size_t gauge = 0;
  for (std::size_t a = 0; a < dams.size(); ++a) {
    const auto& d = dams[a];
    DamSummary q;
    q.name = s.dams[a].name;
    q.lines = d.lines;
    q.cells = d.cells;
    q.crest_length_m = d.length_m;
    for (std::size_t k = 0; k < d.height.size(); ++k)
      if (d.height[k] > 0) {
        q.height_max_m = std::max(q.height_max_m, d.height[k]);
        q.max_depth_m = std::max(q.max_depth_m, res.hazard.max_depth[k]);
      }
    if (d.lines) {
      q.crossed_right_m3 = res.gauge_right[gauge];
      q.crossed_left_m3 = res.gauge_left[gauge];
      q.overflow_m3 = std::max({q.crossed_right_m3, q.crossed_left_m3, 0.0});
      ++gauge;
    }
    out.push_back(q);
  }
  return out;
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

// The run: the grid and releases, the engine from the initial state or a checkpoint, the time series.
class DepthAveragedRun final : public EngineRun {
 public:
  DepthAveragedRun(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);
  engine::SteppingEngine& engine() override { return *engine_; }
  engine::LoopSchedule schedule() const override;
  engine::LoopHooks hooks() override;
  RunSummary finish(engine::StopReason stop, const RunTimes& times) override;

 private:
  const ResolvedScenario& s_;
  std::string out_dir_;
  const RunOptions& opt_;
  terrain::DemReport dem_rep_;
  terrain::Grid grid_;
  terrain::ReleaseReport rel_rep_;
  std::vector<double> h0_;
  OutputInputs output_inputs_;
  engine::Terrain2D t_;
  engine::Sh2dState initial_;  // the release, as the engine starts from it
  engine::Sh2dConfig cfg_;
  std::vector<terrain::ReleaseArea> secondary_;
  std::string hash_;  // the scenario's, in checkpoints
  double continued_from_ = std::numeric_limits<double>::quiet_NaN();  // NaN: not continued
  std::unique_ptr<TimeSeriesWriter> series_;
  std::unique_ptr<engine::Sh2dEngine> engine_;
  std::unique_ptr<nest::NestBoundary> nest_;  // scenario nest: its boundary, recorded every step
  RunSummary sum_;

  void attach_nest(const RunOptions& opt);
};

// The nest's boundary on the grid (the cells whose centres lie inside its polygons, as the nest's
// corridor takes them) and its gauges after the dams'. A nested run's checkpoint is its 3D run's
// (nest/run.cpp): the depth-averaged part writes none (hooks()) and, continued, runs from its start.
void DepthAveragedRun::attach_nest(const RunOptions& opt) {
  if (!opt.restart_path.empty()) {  // before the depth-averaged part: a checkpoint the 3D run cannot read is refused now
    const VofCheckpoint cp = read_checkpoint(opt.restart_path);
    if (!(cp.state.t < s_.end_time_s()))
      throw ScenarioError("checkpoint " + opt.restart_path + " is at t = " + json_number(cp.state.t) + " s, not before numerics.end_time_s");
  }
  const std::string what = "nest.path '" + s_.nest->corridor_path + "'";
  nest_ = std::make_unique<nest::NestBoundary>(grid_, terrain::rasterize_polygons(grid_, s_.nest->corridor_path, s_.scenario.nest().crs(), what),
                                               what);
  for (auto& g : nest_->gauges(cfg_.gauges.size())) cfg_.gauges.push_back(std::move(g));
  nest_->start(0);
  output_inputs_.nest = nest_->cells();
}

DepthAveragedRun::DepthAveragedRun(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt)
    : s_(s), out_dir_(out_dir), opt_(opt) {
  grid_ = cached_grid(s.dem, opt.terrain_cache_dir, dem_rep_);
  h0_ = terrain::rasterize_releases(grid_, s.dem, s.releases, &rel_rep_);
  output_inputs_ = read_output_inputs(s, grid_, h0_);  // a bad point, line or outline: refused before the run
  sum_.nx = grid_.nx;
  sum_.ny = grid_.ny;
  sum_.dx = grid_.dx;
  sum_.crs = grid_.crs_name;
  sum_.release_area_m2 = rel_rep_.area_m2;
  sum_.release_volume_m3 = rel_rep_.volume_m3;
  sum_.notes = rel_rep_.notes;
  t_ = engine_terrain(grid_);
  initial_ = engine::state_from_normal_depth(t_, h0_);
  cfg_ = s.config;
  secondary_ = terrain::secondary_release_areas(grid_, s.dem, s.releases);
  cfg_.secondary = engine_secondary(secondary_);
  cfg_.resistance = resistance_areas(s, output_inputs_.resistance_areas);
  cfg_.cover = erodible_cover(s, output_inputs_.cover_areas);
  place_dams(s, output_inputs_.dams, output_inputs_.structures, t_, cfg_);
  if (s.nest) attach_nest(opt);

  // Checkpoints: the solver's whole state between two steps, with the scenario's hash; the time
  // series so far lies beside it (CHECKPOINT.timeseries.h5), so that a continued run's outputs are
  // the whole run's.
  continued = !opt.restart_path.empty() && !nest_;  // a nest's checkpoint is its 3D run's
  if (!opt.checkpoint_path.empty() || continued) hash_ = scenario_hash(s);
  if (!continued) {
    engine_ = std::make_unique<engine::Sh2dEngine>(t_, cfg_, std::move(initial_));
  } else {
    const ShCheckpoint restart = load_restart(opt, hash_, t_, cfg_.tile);
    try {
      engine_ = std::make_unique<engine::Sh2dEngine>(t_, cfg_, restart.state);
    } catch (const std::invalid_argument& e) {  // the engine's checks of the checkpoint
      throw ScenarioError("checkpoint " + opt.restart_path + ": " + e.what());
    }
    loop = engine::Sh2dEngine::loop_state(restart.state);
    continued_from_ = restart.state.t;
    if (s.timeseries_interval > 0)
      series_ = std::make_unique<TimeSeriesWriter>(out_dir, grid_, t_, cfg_.flow_threshold, opt.restart_path + ".timeseries.h5",
                                                   restart.timeseries_frames);
  }
  if (s.timeseries_interval > 0 && !series_) series_ = std::make_unique<TimeSeriesWriter>(out_dir, grid_, t_, cfg_.flow_threshold);
}

engine::LoopSchedule DepthAveragedRun::schedule() const {
  engine::LoopSchedule sc = engine::loop_schedule(cfg_);
  sc.frame_interval = series_ ? s_.timeseries_interval : 0.0;
  sc.checkpoint_interval = opt_.checkpoint_interval_s;
  return sc;
}

engine::LoopHooks DepthAveragedRun::hooks() {
  engine::LoopHooks h;
  if (series_) h.frame = [this](double time) { series_->write(time, engine_->state()); };
  if (nest_) h.after_step = [this](const engine::StepReport&) { nest_->record(engine_->time(), *engine_); };
  h.checkpoint = [this](const engine::LoopState& st) {
    // The frames first: a checkpoint never refers to frames that are not beside it.
    if (series_) series_->save_copy(opt_.checkpoint_path + ".timeseries.h5");
    write_sh_checkpoint(opt_.checkpoint_path, hash_, series_ ? series_->frames() : 0, engine_->checkpoint(st));
  };
  if (nest_) h.checkpoint = nullptr;  // a nested run writes none (attach_nest)
  return h;
}

RunSummary DepthAveragedRun::finish(engine::StopReason stop, const RunTimes& times) {
  RunSummary sum = std::move(sum_);
  engine::Sh2dResult res = engine_->finish(stop, loop);
  sum.seconds_prepare = times.prepare;
  sum.cpu_seconds = times.cpu;
  int frames = 0;
  if (series_) frames = series_->finish();
  // The structures as the depth-averaged run saw them (before a nest's maps replace its own inside it).
  sum.structures = structure_summaries(s_, grid_, output_inputs_.structures, res.hazard);
  // The 3D nest after the time series is closed (its own HDF5 files open and close meanwhile).
  if (nest_ && stop != engine::StopReason::cancelled) {  // the 3D nest, its maps inside the nest's cells
    bool release_inside = false;
    for (std::size_t k = 0; k < h0_.size(); ++k) release_inside = release_inside || (h0_[k] > 0 && nest_->cells()[k]);
    sum.nest = nest::run_nest(s_, *nest_, res.hazard, (fs::path(out_dir_) / "nest").string(), opt_, release_inside);
    if (sum.nest->cancelled) {  // interrupted in the 3D run: no results (its checkpoint continues it)
      sum.stop = "cancelled";
      return sum;
    }
    if (!std::isnan(sum.nest->continued_from))
      sum.notes.push_back("the 3D nest continued from its checkpoint at t = " + json_number(sum.nest->continued_from) +
                          " s (the depth-averaged run ran again from its start)");
    sum.notes.push_back("inside the 3D nest (" + std::to_string(sum.nest->cells) +
                        " cells) the hazard rasters are the 3D engine's (nest/run.json); outside, the depth-averaged engine's");
  }
  use_flow_path(s_, grid_, h0_, res.hazard.max_depth, series_ ? series_->mass_centres() : std::vector<std::array<double, 3>>{},
                output_inputs_);
  sum.seconds_run = times.run;
  const auto& d = res.diag;
  sum.volume_initial = d.volume_initial;
  sum.volume_final = d.volume_final;
  sum.volume_outflow = d.volume_outflow;
  sum.volume_detrained = d.volume_detrained;
  sum.volume_entrained = d.volume_entrained;
  sum.dams = dam_summaries(s_, output_inputs_.dams, res);
  sum.volume_error = d.volume_error();
  sum.t = d.t;
  sum.steps = d.steps;
  sum.stop = std::string(engine::to_string(d.stop));
  sum.max_speed = d.max_speed;

  hazard_figures(s_, grid_, h0_, res.hazard, sum);
  require_finite_figures({{"final volume", d.volume_final}, {"outflow volume", d.volume_outflow}, {"maximum speed", d.max_speed},
                          {"maximum depth", sum.max_depth}, {"kinetic-energy peak", d.kinetic_energy_peak}, {"runout", sum.runout_m}});

  // Outputs.
  const auto t2 = std::chrono::steady_clock::now();
  const auto outputs = write_hazard_outputs(s_, grid_, h0_, res.hazard, output_inputs_, out_dir_, sum);
  if (!res.detrained.empty()) {
    terrain::write_cog((fs::path(out_dir_) / "detrained_depth.tif").string(), grid_, res.detrained,
                       terrain::BandInfo{"normal thickness left behind in resistance areas (detrainment)", "m"});
    sum.files.push_back("detrained_depth.tif");
  }
  if (!res.cover.empty()) {
    terrain::write_cog((fs::path(out_dir_) / "cover_depth.tif").string(), grid_, terrain::masked_outside(grid_, res.cover),
                       terrain::BandInfo{"erodible cover left at the end (normal thickness)", "m"});
    sum.files.push_back("cover_depth.tif");
  }
  if (series_) {
    // QGIS styles for the frames' GeoTIFFs: the depth and speed maps' classes, on any band chosen.
    figures::write_qml_ramp((fs::path(out_dir_) / "timeseries_depth.qml").string(), figures::hazard_palette("max_depth"));
    figures::write_qml_ramp((fs::path(out_dir_) / "timeseries_speed.qml").string(), figures::hazard_palette("max_speed"));
    for (const char* f : {"timeseries.h5", "timeseries.xmf", "timeseries.nc", "timeseries_depth.tif", "timeseries_depth.qml",
                          "timeseries_speed.tif", "timeseries_speed.qml"})
      sum.files.push_back(f);
  }
  sum.seconds_write = std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count();

  const std::string record = (fs::path(out_dir_) / "run.json").string();
  if (!opt_.iseesnow_id.empty())
    for (auto& f : write_iseesnow(s_, opt_.iseesnow_id, out_dir_, grid_, res, sum.cpu_seconds)) sum.files.push_back(std::move(f));
  write_record(record, s_, dem_rep_, grid_, rel_rep_, res, sum, continued_from_, outputs, frames, secondary_);
  // The report reads the folder with its run.json; the record then lists it, or says why it is not
  // there (a report that cannot be made loses no run).
  if (!s_.report.empty()) {
    if (write_report_output(out_dir_, s_.report, sum)) sum.files.push_back("report.pdf");
    write_record(record, s_, dem_rep_, grid_, rel_rep_, res, sum, continued_from_, outputs, frames, secondary_);
  }
  sum.files.push_back("run.json");
  return sum;
}

}  // namespace

std::unique_ptr<EngineRun> prepare_depth_averaged(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt) {
  return std::make_unique<DepthAveragedRun>(s, out_dir, opt);
}

}  // namespace runout::jobs
