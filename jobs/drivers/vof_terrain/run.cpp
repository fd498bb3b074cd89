#include "jobs/drivers/vof_terrain/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/vof_lab/monitors.hpp"
#include "jobs/drivers/vof_support.hpp"
#include "jobs/drivers/vof_terrain/config.hpp"
#include "jobs/drivers/vof_terrain/hazard.hpp"
#include "jobs/drivers/vof_terrain/record.hpp"
#include "jobs/drivers/vof_terrain/setup.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/formats/lab_frames.hpp"

namespace runout::jobs {

namespace {

namespace vof = engine::vof;
using namespace vof_terrain;
using clk = std::chrono::steady_clock;

// More of the released volume than this through the corridor's edge: run.json says the map is not complete.
constexpr double kCorridorLossNote = 0.02;

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

// The frames' grid: i east, j the layer, k north; the georeferenced frame of the mesh.
FrameGrid frame_grid(const TerrainSetup& su) {
  FrameGrid g;
  g.nx = su.columns.ni;
  g.ny = su.columns.layers;
  g.nz = su.columns.nk;
  g.three_d = true;
  g.cell.assign(std::size_t(g.nx) * std::size_t(g.ny) * std::size_t(g.nz), -1);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) g.cell[g.at(i, j, k)] = su.columns.cell(std::size_t(k) * std::size_t(g.nx) + std::size_t(i), j);
  g.georeferenced = true;
  g.origin_east = su.frame.x;
  g.origin_north = su.frame.y;
  g.origin_elevation = su.frame.z;
  return g;
}

// The run from the first (or restored) step to the end: hazard maps, frames, the outflow, the stop
// rule, checkpoints, progress and cancellation after every step.
struct Stepper {
  const ResolvedScenario& r;
  const RunOptions& opt;
  vof::VofSolver& s;
  const TerrainSetup& su;
  ColumnHazard& hazard;
  LabFrameWriter* frames;
  vof_lab::RunningFigures& fig;
  std::string state_hash;
  double write_every = 0, next_write = 1e300, cp_every = 1e300, next_cp = 1e300;
  double outflow = 0, ke_peak = 0;
  double outflow_corridor = 0, outflow_edge = 0;  ///< through the corridor's edge, through the domain's edge
  bool cancelled = false, settled = false;

  void save(LabCheckpoint& cp) const {
    cp.scenario_hash = state_hash;
    fig.save(cp);
    hazard.save(cp);
    cp.figures["outflow_m3"] = outflow;
    cp.figures["ke_peak"] = ke_peak;
    cp.figures["corridor_outflow_m3"] = outflow_corridor;
    cp.figures["domain_edge_outflow_m3"] = outflow_edge;
  }
  void restore(const LabCheckpoint& cp, const std::string& path) {
    fig.restore(cp, path);
    hazard.restore(cp, path);
    for (const char* k : {"outflow_m3", "ke_peak", "corridor_outflow_m3", "domain_edge_outflow_m3"})
      if (!cp.figures.count(k)) throw ScenarioError("checkpoint " + path + ": damaged (no figure '" + k + "')");
    outflow = cp.figures.at("outflow_m3");
    ke_peak = cp.figures.at("ke_peak");
    outflow_corridor = cp.figures.at("corridor_outflow_m3");
    outflow_edge = cp.figures.at("domain_edge_outflow_m3");
  }
  void write_checkpoint_now() {
    LabCheckpoint cp;
    save(cp);
    cp.state = s.state();
    write_checkpoint(opt.checkpoint_path, cp);
  }
  // The granular kinetic energy and the volume through the boundary in this step (the sides': the
  // corridor's edge apart from the domain's).
  void balance(double dt) {
    const auto& m = s.mesh();
    const int sp = m.patch_index("sides");
    const int s0 = sp < 0 ? 0 : m.patches[std::size_t(sp)].start, s1 = sp < 0 ? 0 : s0 + m.patches[std::size_t(sp)].size;
    for (int f = m.n_internal; f < m.faces(); ++f) {
      const double q = s.granular_flux()[std::size_t(f)] * dt;
      outflow += q;
      if (su.corridor_edge[std::size_t(f)]) outflow_corridor += q;
      else if (f >= s0 && f < s1) outflow_edge += q;
    }
    double ke = 0;
    for (int c = 0; c < m.cells(); ++c) {
      const double a = s.alpha()[std::size_t(c)];
      if (a > 0) ke += 0.5 * a * m.volume[std::size_t(c)] * dot(s.velocity()[std::size_t(c)], s.velocity()[std::size_t(c)]);
    }
    ke_peak = std::max(ke_peak, ke);
    const double frac = r.config.time.stop_fraction;
    settled = frac > 0 && ke_peak > 0 && ke < frac * ke_peak;
  }

  bool operator()(const vof::StepStats& st) {
    fig.step(st);
    hazard.update(st.t, s);
    balance(st.dt);
    if (frames && st.t >= next_write - 1e-12) {
      frames->write(st.t, s);
      next_write += write_every;
    }
    const bool checkpoints = !opt.checkpoint_path.empty();
    const double t_end = r.end_time_s();
    if (checkpoints && st.t >= next_cp - 1e-12 && st.t < t_end - 1e-12) {
      write_checkpoint_now();
      next_cp += cp_every;
    }
    if (!report_step(opt, st, fig.steps, su.mesh.cells()) && st.t < t_end - 1e-12 && !settled) {
      cancelled = true;
      if (checkpoints) write_checkpoint_now();  // the run can continue from here
      return false;
    }
    return !settled;
  }
};

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

}  // namespace

RunSummary run_terrain_vof(const ResolvedScenario& r, const std::string& out_dir, const RunOptions& opt) {
  std::lock_guard turn(petsc_turn());
  const auto t0 = clk::now();
  TerrainSetup su;
  build_terrain_setup(r, su);
  vof::VofSolver s(su.mesh, terrain_config(r, bed_columns(su.columns, su.mesh, su.grid)));
  const bool continued = !opt.restart_path.empty();
  const std::string state_hash = continued || !opt.checkpoint_path.empty() ? terrain_state_hash(r) : std::string();
  LabCheckpoint restart;
  if (continued) {
    restart = read_checkpoint(opt.restart_path);
    if (restart.scenario_hash != state_hash)
      throw ScenarioError("checkpoint " + opt.restart_path +
                          " belongs to another scenario (only numerics.end_time_s, vof.write_interval_s and vof.checkpoint_interval_s may differ)");
    if (!(restart.state.t < r.end_time_s()))
      throw ScenarioError("checkpoint " + opt.restart_path + " is at t = " + json_number(restart.state.t) + " s, not before numerics.end_time_s");
    try {
      s.restore(restart.state);
    } catch (const vof::VofError& e) {
      throw ScenarioError("checkpoint " + opt.restart_path + ": " + e.what());
    }
  } else {
    s.initialise(su.alpha);
  }
  std::vector<ColumnHazard::Tracked> tracked;
  for (const auto& p : su.points) tracked.push_back({p.column, p.mesh_column});
  HazardSettings hs;
  hs.rho = r.scenario.material().density_kg_m3();
  hs.flow_threshold = r.config.flow_threshold;
  ColumnHazard hazard(su.columns, s.mesh(), su.cos_slope, hs, tracked);

  RunSummary sum = summary_of_setup(r, su);
  sum.seconds_prepare = since(t0);

  const double write_every = r.scenario.vof().write_interval_s();
  const FrameGrid fg = frame_grid(su);
  std::unique_ptr<LabFrameWriter> frames;
  if (write_every > 0)
    frames = std::make_unique<LabFrameWriter>(out_dir, fg, &s.mesh().centre,
                                              opt.checkpoint_path.empty() ? std::string() : opt.checkpoint_path + ".fields.h5",
                                              continued ? opt.restart_path + ".fields.h5" : std::string(), restart.state.t);
  vof_lab::RunningFigures fig;
  Stepper step{r, opt, s, su, hazard, frames.get(), fig, state_hash};
  step.write_every = write_every;
  if (continued) {
    step.restore(restart, opt.restart_path);
    if (write_every > 0) step.next_write = next_multiple(write_every, restart.state.t);
  } else {
    hazard.update(0, s);
    if (frames) frames->write(0, s);
    step.next_write = write_every > 0 ? write_every : 1e300;
  }
  const double cp_interval = r.scenario.vof().checkpoint_interval_s();
  step.cp_every = cp_interval > 0 ? cp_interval : opt.checkpoint_interval_s > 0 ? opt.checkpoint_interval_s : 1e300;
  step.next_cp = step.cp_every < 1e300 ? next_multiple(step.cp_every, s.time()) : 1e300;
  const auto t1 = clk::now();
  s.run(r.end_time_s(), [&step](const vof::StepStats& st) { return step(st); });
  sum.seconds_run = since(t1);
  sum.steps = fig.steps;
  sum.t = s.time();
  sum.stop = step.cancelled ? "cancelled" : step.settled ? "kinetic-energy" : "end-time";
  if (step.cancelled) return sum;

  const auto t2 = clk::now();
  hazard.finish(s);
  double v_final = 0;
  for (int c = 0; c < s.mesh().cells(); ++c) v_final += s.alpha()[std::size_t(c)] * s.mesh().volume[std::size_t(c)];
  sum.volume_final = v_final;
  sum.volume_outflow = step.outflow;
  sum.volume_error = std::abs(v_final + step.outflow - su.volume_on_mesh) / su.volume_on_mesh;
  sum.max_speed = 0;
  for (double v : hazard.maps().max_speed) sum.max_speed = std::max(sum.max_speed, v);
  hazard_figures(r, su.grid, su.h0, hazard.maps(), sum);
  require_finite_figures({{"final volume", v_final}, {"outflow volume", step.outflow}, {"maximum speed", sum.max_speed},
                          {"maximum depth", sum.max_depth}, {"runout", sum.runout_m}});
  const auto outputs = write_hazard_outputs(r, su.grid, su.h0, hazard.maps(), su.output_inputs, out_dir, sum);
  write_3d_rasters(su, hazard, out_dir, sum);
  const int n_frames = frames ? frames->finish() : 0;
  if (frames) {
    sum.files.push_back("fields.h5");
    sum.files.push_back("fields.xmf");
  }
  sum.seconds_write = since(t2);
  std::vector<std::string> record_notes;  // what the reader of the maps must know: run.json's notes and the summary's
  if (su.corridor.kind != "none" && step.outflow_corridor > kCorridorLossNote * su.volume_on_mesh) {
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.1f", 100 * step.outflow_corridor / su.volume_on_mesh);
    record_notes.push_back(std::string("the map is not complete: ") + pct +
                           " % of the released volume left the mesh through the corridor's edge (mesh.corridor \"" + su.corridor.kind +
                           "\"): widen mesh.corridor_margin_m, give a wider mesh.corridor_path, or mesh.corridor \"none\"");
  }
  sum.notes.insert(sum.notes.end(), record_notes.begin(), record_notes.end());
  TerrainRunFacts facts{su, hazard, fig, sum, continued ? restart.state.t : std::numeric_limits<double>::quiet_NaN(),
                        outputs, n_frames, step.outflow_corridor, step.outflow_edge, record_notes};
  write_terrain_record(out_dir + "/run.json", r, facts);
  sum.files.push_back("run.json");
  return sum;
}

}  // namespace runout::jobs
