#include "jobs/drivers/vof_lab/run.hpp"

#include <google/protobuf/util/json_util.h>

#include <chrono>
#include <cmath>
#include <mutex>

#include "jobs/digest/sha256.hpp"
#include "jobs/drivers/record_head.hpp"
#include "jobs/drivers/vof_support.hpp"
#include "jobs/drivers/vof_lab/figures.hpp"
#include "jobs/drivers/vof_lab/monitors.hpp"
#include "jobs/drivers/vof_lab/results.hpp"
#include "jobs/drivers/vof_lab/setup.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/formats/lab_frames.hpp"
#include "jobs/formats/run_record.hpp"

namespace runout::jobs {

namespace {

namespace vof = engine::vof;
using namespace vof_lab;
using clk = std::chrono::steady_clock;

double since(clk::time_point t0) { return std::chrono::duration<double>(clk::now() - t0).count(); }

// What a checkpoint must match: the scenario without the end time and the write and checkpoint
// intervals (a run may be continued further than first planned).
std::string lab_state_hash(const ResolvedScenario& r) {
  auto sc = r.scenario;
  sc.mutable_lab()->clear_end_time_s();
  sc.mutable_lab()->clear_write_interval_s();
  sc.mutable_lab()->clear_checkpoint_interval_s();
  std::string json;
  google::protobuf::util::JsonPrintOptions po;
  po.preserve_proto_field_names = true;
  (void)google::protobuf::util::MessageToJsonString(sc, &json, po);
  return sha256_hex(json);
}

// The checkpoint to continue from, checked against the scenario.
LabCheckpoint read_restart(const std::string& path, const std::string& state_hash, const v1::Lab& L) {
  LabCheckpoint restart = read_checkpoint(path);
  if (restart.scenario_hash != state_hash)
    throw ScenarioError("checkpoint " + path + " belongs to another scenario (only end_time_s, write_interval_s and "
                        "checkpoint_interval_s may differ)");
  if (!(restart.state.t < L.end_time_s()))
    throw ScenarioError("checkpoint " + path + " is at t = " + json_number(restart.state.t) + " s, not before lab.end_time_s");
  return restart;
}

// The run from the first (or restored) step to the end: frames, monitors, checkpoints, progress and
// cancellation after every step.
struct Stepper {
  const v1::Lab& L;
  const RunOptions& opt;
  vof::VofSolver& s;
  const LabSetup& su;
  LabFrameWriter& frames;
  RunningFigures& fig;
  LabMonitors& mon;
  std::string state_hash;
  double next_write = 1e300, cp_every = 1e300, next_cp = 1e300;
  bool cancelled = false;

  void write_checkpoint_now() {
    LabCheckpoint cp;
    cp.scenario_hash = state_hash;
    fig.save(cp);
    mon.save(cp);
    cp.state = s.state();
    write_checkpoint(opt.checkpoint_path, cp);
  }

  bool operator()(const vof::StepStats& st) {
    fig.step(st);
    if (st.t >= next_write - 1e-12) {
      frames.write(st.t, s);
      next_write += L.write_interval_s();
    }
    mon.after_step(st.t, s);
    const bool checkpoints = !opt.checkpoint_path.empty();
    if (checkpoints && st.t >= next_cp - 1e-12 && st.t < L.end_time_s() - 1e-12) {
      write_checkpoint_now();
      next_cp += cp_every;
    }
    if (!report_step(opt, st, fig.steps, su.m.cells()) && st.t < L.end_time_s() - 1e-12) {  // on the last step the run is done anyway
      cancelled = true;
      if (checkpoints) write_checkpoint_now();  // the run can continue from here
      return false;
    }
    return true;
  }
};

void write_timings(const RunSummary& sum, const RunningFigures& fig, int cells, v1::RunRecord& rec) {
  auto* ti = rec.mutable_timings_s();
  ti->set_prepare(sum.seconds_prepare);
  ti->set_run(sum.seconds_run);
  ti->set_write(sum.seconds_write);
  ti->set_microseconds_per_cell_step(fig.steps ? 1e6 * sum.seconds_run / fig.steps / cells : NAN);
  ti->set_microseconds_per_active_cell_step(fig.active_sum > 0 ? 1e6 * sum.seconds_run / fig.active_sum : NAN);
}

}  // namespace

RunSummary run_lab(const ResolvedScenario& r, const std::string& out_dir, const RunOptions& opt) {
  std::lock_guard turn(petsc_turn());
  const auto t0 = clk::now();
  const auto& L = r.scenario.lab();
  LabSetup su;
  build_setup(L, su);
  const LabGrid& g = su.g;
  vof::VofSolver s(su.m, su.config);
  const std::string state_hash = lab_state_hash(r);
  const bool continued = !opt.restart_path.empty();
  LabCheckpoint restart;
  if (continued) {
    restart = read_restart(opt.restart_path, state_hash, L);
    try {
      s.restore(restart.state);
    } catch (const vof::VofError& e) {
      throw ScenarioError("checkpoint " + opt.restart_path + ": " + e.what());
    }
  } else {
    s.initialise(su.alpha);
  }

  RunSummary sum;
  sum.nx = g.nx;
  sum.ny = g.ny * g.nz;
  sum.dx = g.dx;
  sum.crs = "channel coordinates";
  sum.release_volume_m3 = su.v0;
  sum.volume_initial = su.v0;
  sum.seconds_prepare = since(t0);
  // With checkpoints the frames are written next to the checkpoint (CHECKPOINT.fields.h5), so that
  // a continued run carries on with them; a run continued from RESTART takes RESTART.fields.h5's
  // frames up to its time.
  LabFrameWriter frames(out_dir, g, L.has_chute() ? &su.m.centre : nullptr,
                        opt.checkpoint_path.empty() ? std::string() : opt.checkpoint_path + ".fields.h5",
                        continued ? opt.restart_path + ".fields.h5" : std::string(), restart.state.t);
  RunningFigures fig;
  LabMonitors mon(su, L, s.time());
  Stepper step{L, opt, s, su, frames, fig, mon, state_hash};
  step.next_write = L.write_interval_s() > 0 ? L.write_interval_s() : 1e300;
  if (continued) {
    fig.restore(restart, opt.restart_path);
    mon.restore(restart, opt.restart_path);
    if (L.write_interval_s() > 0)  // the next regular frame after the checkpoint
      step.next_write = next_multiple(L.write_interval_s(), restart.state.t);
  } else {
    frames.write(0, s);
  }
  step.cp_every = L.checkpoint_interval_s() > 0 ? L.checkpoint_interval_s() : opt.checkpoint_interval_s > 0 ? opt.checkpoint_interval_s : 1e300;
  step.next_cp = step.cp_every < 1e300 ? next_multiple(step.cp_every, s.time()) : 1e300;
  const auto t1 = clk::now();
  s.run(L.end_time_s(), [&step](const vof::StepStats& st) { return step(st); });
  sum.seconds_run = since(t1);
  sum.steps = fig.steps;
  sum.t = s.time();
  sum.stop = step.cancelled ? "cancelled" : "end-time";
  if (step.cancelled) return sum;

  const auto t2 = clk::now();
  const Deposit dep = deposit(su, s);
  sum.volume_final = dep.volume;
  sum.volume_error = su.has_inflow ? NAN : std::abs(dep.volume - su.v0) / su.v0;  // material comes in: no conservation figure
  sum.max_speed = fig.peak;
  sum.runout_m = dep.front;
  sum.max_depth = dep.height;
  const int n_frames = frames.finish();
  write_state_figure(out_dir + "/figure.png", s, g, std::max(fig.peak, 0.01));
  const std::string title = figure_title(r, g, s.time());

  v1::RunRecord rec = run_record_head(r, "vof");
  write_mesh(su, rec);
  fig.write(rec);
  rec.mutable_solver()->set_simulated_s(s.time());
  rec.mutable_solver()->set_stop(sum.stop);
  if (continued) rec.mutable_solver()->set_continued_from_t_s(restart.state.t);
  write_deposit(dep, su, n_frames, rec);
  write_stations(L, su, s, rec);
  mon.write(rec);
  figures::PlanFigure plan;  // comparison.png of a 3D run
  plan.title = title;
  if (g.three_d) write_chute(L, su, s, plan, rec);
  sum.files = {"fields.h5", "fields.xmf", "figure.png", "run.json", "comparison.png"};
  sum.seconds_write = since(t2);

  write_timings(sum, fig, su.m.cells(), rec);
  for (const auto& f : sum.files) rec.add_outputs(f);
  rec.mutable_execution()->set_petsc_options(petsc_options());
  write_run_record(out_dir + "/run.json", rec);
  if (g.three_d) figures::write_plan_figure(out_dir + "/comparison.png", plan);
  else write_section_comparison(out_dir + "/comparison.png", title, L, su, s, dep, mon);
  return sum;
}

}  // namespace runout::jobs
