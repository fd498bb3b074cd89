// The 3D engine on the DEM (scenario engine "vof" without `lab`) as a run set-up
// (jobs/drivers/engine_run.hpp): grid, release and terrain-following mesh (setup.hpp), the hazard
// maps integrated through the depth after every step (hazard.hpp), and the outputs: the
// depth-averaged engine's rasters, outline and map (jobs/drivers/hazard_outputs.hpp),
// max_surface_speed.tif, max_ground_stress.tif, the 3D frames (fields.h5 + fields.xmf, in the grid's
// CRS with z up) and run.json (record.hpp).
#include "jobs/drivers/engine_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>

#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/vof_lab/monitors.hpp"
#include "jobs/drivers/vof_support.hpp"
#include "jobs/drivers/nest/inflow.hpp"
#include "jobs/drivers/vof_terrain/config.hpp"
#include "jobs/drivers/vof_terrain/hazard.hpp"
#include "jobs/drivers/vof_terrain/loads.hpp"
#include "jobs/drivers/vof_terrain/record.hpp"
#include "jobs/drivers/vof_terrain/setup.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/formats/vof_frames.hpp"
#include "engine/vof/stepping.hpp"

namespace runout::jobs {

namespace {

namespace vof = engine::vof;
using namespace vof_terrain;
using clk = std::chrono::steady_clock;

// More of the released volume than this through the corridor's edge: run.json says the map is not complete.
constexpr double kCorridorLossNote = 0.02;
// The structures' loads go to structure_loads.csv this often [s] (their peaks are taken every step).
constexpr double kLoadsInterval = 0.1;

double since(clk::time_point t0) { return std::chrono::duration<double>(clk::now() - t0).count(); }

// What a checkpoint must match: the scenario without the end time and the write and checkpoint
// intervals (a run may be continued further than first planned), and the input files.
std::string terrain_state_hash(const ResolvedScenario& r) {
  ResolvedScenario q = r;
  q.scenario.mutable_numerics()->clear_end_time_s();
  q.scenario.mutable_vof()->clear_write_interval_s();
  q.scenario.mutable_vof()->clear_checkpoint_interval_s();
  return scenario_hash(q);
}

// The frames' grid: i east, j the layer, k north, over the meshed columns' bounding box (a corridor
// or a nest is a small part of the domain); the georeferenced frame of the mesh.
FrameGrid frame_grid(const TerrainSetup& su) {
  const auto& c = su.columns;
  int i0 = c.ni, i1 = -1, k0 = c.nk, k1 = -1;
  for (int k = 0; k < c.nk; ++k)
    for (int i = 0; i < c.ni; ++i)
      for (int j = 0; j < c.layers; ++j)
        if (c.cell(std::size_t(k) * std::size_t(c.ni) + std::size_t(i), j) >= 0) {
          i0 = std::min(i0, i), i1 = std::max(i1, i), k0 = std::min(k0, k), k1 = std::max(k1, k);
          break;
        }
  FrameGrid g;
  g.nx = i1 - i0 + 1;
  g.ny = c.layers;
  g.nz = k1 - k0 + 1;
  g.three_d = true;
  g.cell.assign(std::size_t(g.nx) * std::size_t(g.ny) * std::size_t(g.nz), -1);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) g.cell[g.at(i, j, k)] = c.cell(std::size_t(k + k0) * std::size_t(c.ni) + std::size_t(i + i0), j);
  g.georeferenced = true;
  g.origin_east = su.frame.x;
  g.origin_north = su.frame.y;
  g.origin_elevation = su.frame.z;
  return g;
}

// The rasters only the 3D engine gives, beside the depth-averaged engine's.
void write_3d_rasters(const TerrainSetup& su, const ColumnHazard& hz, const std::string& out_dir, RunSummary& sum) {
  terrain::write_cog(out_dir + "/max_surface_speed.tif", su.grid, terrain::masked_outside(su.grid, hz.max_surface_speed()),
                     {"maximum speed at the flow's surface [m/s]", "m/s"});
  terrain::write_cog(out_dir + "/max_ground_stress.tif", su.grid, terrain::masked_outside(su.grid, hz.max_ground_stress()),
                     {"maximum normal stress of the flow on the ground [Pa]", "Pa"});
  sum.files.push_back("max_surface_speed.tif");
  sum.files.push_back("max_ground_stress.tif");
}

// The run summary's figures of the set-up: the grid, the release, the mesh and its corridor.
RunSummary summary_of_setup(const ResolvedScenario& r, const TerrainSetup& su) {
  RunSummary sum;
  sum.nx = su.grid.nx;
  sum.ny = su.grid.ny;
  sum.dx = su.grid.dx;
  sum.crs = su.grid.crs_name;
  sum.release_area_m2 = su.release.area_m2;
  sum.release_volume_m3 = su.release.volume_m3;
  sum.volume_initial = su.volume_on_mesh;
  sum.notes = su.release.notes;
  sum.notes.push_back("mesh: " + std::to_string(su.columns_mesh.kept_columns()) + " columns x " + std::to_string(su.columns.layers) +
                      " layers = " + std::to_string(su.mesh.cells()) + " cells (corridor \"" + su.corridor.kind + "\": " +
                      std::to_string(su.columns_mesh.kept_columns()) + " of the domain's " + std::to_string(su.domain_columns) + " columns)");
  if (su.columns.refinement > 1 || (r.scenario.mesh().has_refinement() && r.scenario.mesh().refinement() == 0))
    sum.notes.push_back("mesh: columns of " + json_number(su.columns_mesh.dx) + " m, " + std::to_string(su.columns.refinement) + " x " +
                        std::to_string(su.columns.refinement) + " per grid cell (" + su.refinement_reason + "); the maps integrate them per grid cell");
  return sum;
}

// The run: grid, release, mesh and the solver from the initial state or a checkpoint, the hazard
// maps integrated through the depth after every step, the volume through the boundary, frames.
class TerrainRun final : public EngineRun {
 public:
  TerrainRun(const ResolvedScenario& r, const std::string& out_dir, const RunOptions& opt);
  engine::SteppingEngine& engine() override { return *step_; }
  engine::LoopSchedule schedule() const override;
  engine::LoopHooks hooks() override;
  RunSummary finish(engine::StopReason stop, const RunTimes& times) override;

 private:
  // The volume through the boundary in this step (the sides': the corridor's edge apart from the domain's).
  void balance(double dt);
  void save(VofCheckpoint& cp) const;
  void restore(const VofCheckpoint& cp, const std::string& path);
  std::vector<std::string> corridor_notes() const;

  std::lock_guard<std::mutex> turn_{petsc_turn()};  // first: held until the solver is gone
  const ResolvedScenario& r_;
  std::string out_dir_;
  const RunOptions& opt_;
  TerrainSetup su_;
  std::unique_ptr<vof::VofBackend> s_;
  std::string state_hash_;
  double continued_from_ = std::numeric_limits<double>::quiet_NaN();
  std::unique_ptr<ColumnHazard> hazard_;
  std::unique_ptr<StructureLoads> loads_;  // scenario structures[]
  FrameGrid frame_grid_;  // the frames' grid (the writer keeps a reference)
  std::unique_ptr<VofFrameWriter> frames_;
  RunningFigures fig_;
  std::unique_ptr<vof::VofStepping> step_;
  double outflow_ = 0;
  double outflow_corridor_ = 0, outflow_edge_ = 0;  // through the corridor's edge, through the domain's edge
  double nest_in_ = 0;  // a nest's: what entered through its boundary
};

TerrainRun::TerrainRun(const ResolvedScenario& r, const std::string& out_dir, const RunOptions& opt) : r_(r), out_dir_(out_dir), opt_(opt) {
  build_terrain_setup(r, su_);
  vof::VofConfig config = terrain_config(r, bed_columns(su_.columns, su_.mesh, su_.grid));
  if (r.nest_part) {  // the nest's boundary takes the depth-averaged run's flux
    if (!opt.nest || !opt.nest->boundary) throw ScenarioError("nest: the 3D part of a nested run needs its depth-averaged run's record");
    config.bc["nest"] = nest::nest_inflow(su_, *opt.nest->boundary);
    config.t_start = opt.nest->start_time;
    config.dt_max = std::min(config.dt_max, nest::nest_max_step(su_, *opt.nest->boundary, config.max_co));
    if (su_.mesh.patch_index("sides") < 0) config.bc.erase("sides");  // a nest inside the domain: its boundary is all "nest"
  }
  s_ = vof::make_vof_backend(su_.mesh, config);
  continued = !opt.restart_path.empty();
  state_hash_ = continued || !opt.checkpoint_path.empty() ? terrain_state_hash(r) : std::string();
  VofCheckpoint restart;
  if (continued) {
    restart = read_checkpoint(opt.restart_path);
    if (restart.scenario_hash != state_hash_)
      throw ScenarioError("checkpoint " + opt.restart_path +
                          " belongs to another scenario (only numerics.end_time_s, vof.write_interval_s and vof.checkpoint_interval_s may differ)");
    if (!(restart.state.t < r.end_time_s()))
      throw ScenarioError("checkpoint " + opt.restart_path + " is at t = " + json_number(restart.state.t) + " s, not before numerics.end_time_s");
    try {
      s_->restore(restart.state);
    } catch (const vof::VofError& e) {
      throw ScenarioError("checkpoint " + opt.restart_path + ": " + e.what());
    }
    continued_from_ = restart.state.t;
    if (opt.nest) opt.nest->continued_from = continued_from_;
  } else {
    s_->initialise(su_.alpha);
  }
  std::vector<ColumnHazard::Tracked> tracked;
  for (const auto& p : su_.points) tracked.push_back({p.column, p.mesh_column});
  HazardSettings hs;
  hs.rho = r.scenario.material().density_kg_m3();
  hs.flow_threshold = r.config.flow_threshold;
  hazard_ = std::make_unique<ColumnHazard>(su_.columns, s_->mesh(), su_.cos_slope, hs, tracked);
  loads_ = std::make_unique<StructureLoads>(su_, kLoadsInterval);
  const double write_every = r.scenario.vof().write_interval_s();
  frame_grid_ = frame_grid(su_);
  if (write_every > 0)
    frames_ = std::make_unique<VofFrameWriter>(out_dir, frame_grid_, &s_->mesh().centre,
                                               opt.checkpoint_path.empty() ? std::string() : opt.checkpoint_path + ".fields.h5",
                                               continued ? opt.restart_path + ".fields.h5" : std::string(), restart.state.t);
  if (continued) {
    restore(restart, opt.restart_path);
  } else {
    hazard_->update(0, *s_);
  }
  step_ = std::make_unique<vof::VofStepping>(*s_, fig_.steps);
}

void TerrainRun::save(VofCheckpoint& cp) const {
  cp.scenario_hash = state_hash_;
  fig_.save(cp);
  hazard_->save(cp);
  loads_->save(cp);
  cp.figures["outflow_m3"] = outflow_;
  cp.figures["ke_peak"] = loop.kinetic_energy_peak;
  cp.figures["corridor_outflow_m3"] = outflow_corridor_;
  cp.figures["domain_edge_outflow_m3"] = outflow_edge_;
  if (r_.nest_part) cp.figures["nest_inflow_m3"] = nest_in_;
}

void TerrainRun::restore(const VofCheckpoint& cp, const std::string& path) {
  fig_.restore(cp, path);
  hazard_->restore(cp, path);
  loads_->restore(cp, path);
  for (const char* k : {"outflow_m3", "ke_peak", "corridor_outflow_m3", "domain_edge_outflow_m3"})
    if (!cp.figures.count(k)) throw ScenarioError("checkpoint " + path + ": damaged (no figure '" + k + "')");
  outflow_ = cp.figures.at("outflow_m3");
  loop.kinetic_energy_peak = cp.figures.at("ke_peak");
  outflow_corridor_ = cp.figures.at("corridor_outflow_m3");
  outflow_edge_ = cp.figures.at("domain_edge_outflow_m3");
  if (r_.nest_part) {
    if (!cp.figures.count("nest_inflow_m3")) throw ScenarioError("checkpoint " + path + ": damaged (no figure 'nest_inflow_m3')");
    nest_in_ = cp.figures.at("nest_inflow_m3");
  }
}

void TerrainRun::balance(double dt) {
  const auto& m = s_->mesh();
  const int sp = m.patch_index("sides");
  const int s0 = sp < 0 ? 0 : m.patches[std::size_t(sp)].start, s1 = sp < 0 ? 0 : s0 + m.patches[std::size_t(sp)].size;
  const int np = m.patch_index("nest");
  const int n0 = np < 0 ? 0 : m.patches[std::size_t(np)].start, n1 = np < 0 ? 0 : n0 + m.patches[std::size_t(np)].size;
  for (int f = m.n_internal; f < m.faces(); ++f) {
    const double q = s_->granular_flux()[std::size_t(f)] * dt;
    outflow_ += q;
    if (f >= n0 && f < n1 && q < 0) nest_in_ -= q;
    if (su_.corridor_edge[std::size_t(f)]) outflow_corridor_ += q;
    else if (f >= s0 && f < s1) outflow_edge_ += q;
  }
}

engine::LoopSchedule TerrainRun::schedule() const {
  engine::LoopSchedule sc;
  sc.t_end = r_.end_time_s();
  sc.stop_fraction = r_.config.time.stop_fraction;
  sc.frame_interval = frames_ ? r_.scenario.vof().write_interval_s() : 0.0;
  const double cp_interval = r_.scenario.vof().checkpoint_interval_s();
  sc.checkpoint_interval = cp_interval > 0 ? cp_interval : opt_.checkpoint_interval_s;
  return sc;
}

engine::LoopHooks TerrainRun::hooks() {
  engine::LoopHooks h;
  h.after_step = [this](const engine::StepReport& r) {
    fig_.step(step_->last());
    hazard_->update(r.t, *s_);
    if (!loads_->empty()) loads_->update(r.t, r.dt, *s_, *hazard_);
    balance(r.dt);
  };
  if (frames_) h.frame = [this](double t) { frames_->write(t, *s_); };
  h.checkpoint = [this](const engine::LoopState&) {
    VofCheckpoint cp;
    save(cp);  // the loop's figures are `loop`'s
    cp.state = s_->state();
    write_checkpoint(opt_.checkpoint_path, cp);
  };
  return h;
}

// What the reader of the maps must know about the corridor: run.json's notes and the summary's.
std::vector<std::string> TerrainRun::corridor_notes() const {
  std::vector<std::string> notes;
  if (su_.corridor.kind != "none" && outflow_corridor_ > kCorridorLossNote * su_.volume_on_mesh) {
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.1f", 100 * outflow_corridor_ / su_.volume_on_mesh);
    notes.push_back(std::string("the map is not complete: ") + pct +
                    " % of the released volume left the mesh through the corridor's edge (mesh.corridor \"" + su_.corridor.kind +
                    "\"): widen mesh.corridor_margin_m, give a wider mesh.corridor_path, or mesh.corridor \"none\"");
  }
  return notes;
}

RunSummary TerrainRun::finish(engine::StopReason stop, const RunTimes& times) {
  const vof::VofBackend& s = *s_;
  RunSummary sum = summary_of_setup(r_, su_);
  sum.seconds_prepare = times.prepare;
  sum.seconds_run = times.run;
  sum.steps = fig_.steps;
  sum.t = s.time();
  sum.stop = std::string(engine::to_string(stop));
  if (stop == engine::StopReason::cancelled) return sum;

  const auto t2 = clk::now();
  hazard_->finish(s);
  double v_final = 0;
  for (int c = 0; c < s.mesh().cells(); ++c) v_final += s.alpha()[std::size_t(c)] * s.mesh().volume[std::size_t(c)];
  sum.volume_final = v_final;
  sum.volume_outflow = outflow_;
  // A nest's own balance counts what entered it; its release may be none.
  sum.volume_error = std::abs(v_final + outflow_ - su_.volume_on_mesh) / std::max(su_.volume_on_mesh + nest_in_, 1e-300);
  if (opt_.nest) {
    opt_.nest->maps = hazard_->maps();
    opt_.nest->inflow_m3 = nest_in_;
    opt_.nest->volume_error = sum.volume_error;
    opt_.nest->mesh_cells = su_.mesh.cells();
    opt_.nest->column_width_m = su_.columns_mesh.dx;
    opt_.nest->first_layer_m = su_.columns.levels[1];
    opt_.nest->band_height_m = su_.columns.levels.back();
  }
  sum.max_speed = 0;
  for (double v : hazard_->maps().max_speed) sum.max_speed = std::max(sum.max_speed, v);
  hazard_figures(r_, su_.grid, su_.h0, hazard_->maps(), sum);
  require_finite_figures({{"final volume", v_final}, {"outflow volume", outflow_}, {"maximum speed", sum.max_speed},
                          {"maximum depth", sum.max_depth}, {"runout", sum.runout_m}});
  sum.structures = structure_summaries(r_, su_.grid, su_.output_inputs.structures, hazard_->maps());
  if (!loads_->empty()) loads_->summarise(sum.structures);  // before the maps, which show the loads
  const auto outputs = write_hazard_outputs(r_, su_.grid, su_.h0, hazard_->maps(), su_.output_inputs, out_dir_, sum);
  write_3d_rasters(su_, *hazard_, out_dir_, sum);
  if (!loads_->empty()) {
    sum.files.push_back(loads_->write_csv(out_dir_));
    if (r_.maps)
      for (auto& f : loads_->write_plot(out_dir_, r_.scenario.name().empty() ? "3D run" : r_.scenario.name())) sum.files.push_back(std::move(f));
  }
  const int n_frames = frames_ ? frames_->finish() : 0;
  if (frames_) {
    sum.files.push_back("fields.h5");
    sum.files.push_back("fields.xmf");
  }
  sum.seconds_write = since(t2);
  const std::vector<std::string> record_notes = corridor_notes();
  sum.notes.insert(sum.notes.end(), record_notes.begin(), record_notes.end());
  TerrainRunFacts facts{su_, *hazard_, fig_, sum, continued_from_, outputs, n_frames, outflow_corridor_, outflow_edge_, record_notes, s_.get()};
  write_terrain_record(out_dir_ + "/run.json", r_, facts);
  sum.files.push_back("run.json");
  return sum;
}

}  // namespace

std::unique_ptr<EngineRun> prepare_vof_terrain(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt) {
  return std::make_unique<TerrainRun>(s, out_dir, opt);
}

}  // namespace runout::jobs
