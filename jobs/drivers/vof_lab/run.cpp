// The 3D engine's laboratory set-ups (scenario engine "vof", block `lab`) as a run set-up
// (jobs/drivers/engine_run.hpp): mesh and conditions from the scenario (setup.hpp, config.hpp), the
// monitors (monitors.hpp), checkpoints, and the outputs: fields.h5 + fields.xmf
// (jobs/formats/vof_frames.hpp), figure.png and comparison.png (figures.hpp) and run.json
// (jobs/formats/run_record.hpp) with the figures the validation cases compare (results.hpp).
#include "jobs/drivers/engine_run.hpp"

#include <google/protobuf/util/json_util.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>

#include "jobs/digest/sha256.hpp"
#include "jobs/drivers/record_head.hpp"
#include "jobs/drivers/vof_support.hpp"
#include "jobs/drivers/vof_lab/figures.hpp"
#include "jobs/drivers/vof_lab/monitors.hpp"
#include "jobs/drivers/vof_lab/nest.hpp"
#include "jobs/drivers/vof_lab/results.hpp"
#include "jobs/drivers/vof_lab/setup.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/formats/vof_frames.hpp"
#include "jobs/formats/run_record.hpp"
#include "engine/vof/stepping.hpp"

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
VofCheckpoint read_restart(const std::string& path, const std::string& state_hash, const v1::Lab& L) {
  VofCheckpoint restart = read_checkpoint(path);
  if (restart.scenario_hash != state_hash)
    throw ScenarioError("checkpoint " + path + " belongs to another scenario (only end_time_s, write_interval_s and "
                        "checkpoint_interval_s may differ)");
  if (!(restart.state.t < L.end_time_s()))
    throw ScenarioError("checkpoint " + path + " is at t = " + json_number(restart.state.t) + " s, not before lab.end_time_s");
  return restart;
}

void write_timings(const RunSummary& sum, const RunningFigures& fig, int cells, v1::RunRecord& rec) {
  auto* ti = rec.mutable_timings_s();
  ti->set_prepare(sum.seconds_prepare);
  ti->set_run(sum.seconds_run);
  ti->set_write(sum.seconds_write);
  ti->set_microseconds_per_cell_step(fig.steps ? 1e6 * sum.seconds_run / fig.steps / cells : NAN);
  ti->set_microseconds_per_active_cell_step(fig.active_sum > 0 ? 1e6 * sum.seconds_run / fig.active_sum : NAN);
}

// The run: mesh, conditions and the solver from the initial state or a checkpoint, frames, figures
// and monitors.
class LabRun final : public EngineRun {
 public:
  LabRun(const ResolvedScenario& r, const std::string& out_dir, const RunOptions& opt);
  engine::SteppingEngine& engine() override { return *step_; }
  engine::LoopSchedule schedule() const override;
  engine::LoopHooks hooks() override;
  RunSummary finish(engine::StopReason stop, const RunTimes& times) override;

 private:
  std::lock_guard<std::mutex> turn_{petsc_turn()};  // first: held until the solver is gone
  const ResolvedScenario& r_;
  const v1::Lab L_;  // the lab block, or with a nest the part the 3D run takes (nest.hpp)
  std::string out_dir_;
  const RunOptions& opt_;
  LabSetup su_;
  std::unique_ptr<vof::VofBackend> s_;
  std::string state_hash_;
  double continued_from_ = 0;
  std::unique_ptr<VofFrameWriter> frames_;
  RunningFigures fig_;
  std::unique_ptr<LabMonitors> mon_;
  std::unique_ptr<vof::VofStepping> step_;
  std::unique_ptr<FaceRecord> face_;  // a nest's: the depth-averaged run's record at its face
  FaceBalance balance_;
};

LabRun::LabRun(const ResolvedScenario& r, const std::string& out_dir, const RunOptions& opt)
    : r_(r), L_(r.scenario.lab().has_nest() ? nest_part(r.scenario.lab()) : r.scenario.lab()), out_dir_(out_dir), opt_(opt) {
  build_setup(L_, su_);
  if (r.scenario.lab().has_nest()) {  // the chute above on the depth-averaged engine (run again when continued: it is deterministic)
    face_ = std::make_unique<FaceRecord>(record_face(r.scenario.lab(), su_.mat));
    attach_face(*face_, L_, su_.m, su_.config);
  }
  s_ = vof::make_vof_backend(su_.m, su_.config);
  state_hash_ = lab_state_hash(r);
  continued = !opt.restart_path.empty();
  VofCheckpoint restart;
  if (continued) {
    restart = read_restart(opt.restart_path, state_hash_, L_);
    try {
      s_->restore(restart.state);
    } catch (const vof::VofError& e) {
      throw ScenarioError("checkpoint " + opt.restart_path + ": " + e.what());
    }
    continued_from_ = restart.state.t;
    if (face_) {
      try {
        balance_.in = restart.figures.at("nest_inflow_m3");
        balance_.out = restart.figures.at("nest_outflow_m3");
      } catch (const std::out_of_range&) {
        throw ScenarioError("checkpoint " + opt.restart_path + ": has no nest balance (written by a run without lab.nest?)");
      }
    }
  } else {
    s_->initialise(su_.alpha);
  }
  // With checkpoints the frames are written next to the checkpoint (CHECKPOINT.fields.h5), so that
  // a continued run carries on with them; a run continued from RESTART takes RESTART.fields.h5's
  // frames up to its time.
  frames_ = std::make_unique<VofFrameWriter>(out_dir, su_.g, L_.has_chute() ? &su_.m.centre : nullptr,
                                             opt.checkpoint_path.empty() ? std::string() : opt.checkpoint_path + ".fields.h5",
                                             continued ? opt.restart_path + ".fields.h5" : std::string(), restart.state.t);
  mon_ = std::make_unique<LabMonitors>(su_, L_, s_->time());
  if (continued) {
    fig_.restore(restart, opt.restart_path);
    mon_->restore(restart, opt.restart_path);
  }
  step_ = std::make_unique<vof::VofStepping>(*s_, fig_.steps);
}

engine::LoopSchedule LabRun::schedule() const {
  engine::LoopSchedule sc;
  sc.t_end = L_.end_time_s();
  sc.frame_interval = L_.write_interval_s();
  sc.checkpoint_interval = L_.checkpoint_interval_s() > 0 ? L_.checkpoint_interval_s() : opt_.checkpoint_interval_s;
  return sc;
}

engine::LoopHooks LabRun::hooks() {
  engine::LoopHooks h;
  h.after_step = [this](const engine::StepReport& r) {
    fig_.step(step_->last());
    mon_->after_step(r.t, *s_);
    if (face_) balance_.step(*s_, r.dt);
  };
  h.frame = [this](double t) { frames_->write(t, *s_); };
  h.checkpoint = [this](const engine::LoopState&) {
    VofCheckpoint cp;
    cp.scenario_hash = state_hash_;
    fig_.save(cp);
    mon_->save(cp);
    if (face_) cp.figures["nest_inflow_m3"] = balance_.in, cp.figures["nest_outflow_m3"] = balance_.out;
    cp.state = s_->state();
    write_checkpoint(opt_.checkpoint_path, cp);
  };
  return h;
}

RunSummary LabRun::finish(engine::StopReason stop, const RunTimes& times) {
  const LabGrid& g = su_.g;
  const vof::VofBackend& s = *s_;
  RunSummary sum;
  sum.nx = g.nx;
  sum.ny = g.ny * g.nz;
  sum.dx = g.dx;
  sum.crs = "channel coordinates";
  sum.release_volume_m3 = su_.v0;
  sum.volume_initial = su_.v0;
  sum.seconds_prepare = times.prepare;
  sum.seconds_run = times.run;
  sum.steps = fig_.steps;
  sum.t = s.time();
  sum.stop = std::string(engine::to_string(stop));
  if (stop == engine::StopReason::cancelled) return sum;

  const auto t2 = clk::now();
  const Deposit dep = deposit(su_, s);
  sum.volume_final = dep.volume;
  sum.volume_error = su_.has_inflow ? NAN : std::abs(dep.volume - su_.v0) / su_.v0;  // material comes in: no conservation figure
  sum.max_speed = fig_.peak;
  sum.runout_m = dep.front;
  sum.max_depth = dep.height;
  const int n_frames = frames_->finish();
  write_state_figure(out_dir_ + "/figure.png", s, g, std::max(fig_.peak, 0.01));
  const std::string title = figure_title(r_, g, s.time());

  v1::RunRecord rec = run_record_head(r_, "vof");
  write_mesh(su_, rec);
  fig_.write(rec);
  rec.mutable_solver()->set_simulated_s(s.time());
  rec.mutable_solver()->set_stop(sum.stop);
  if (continued) rec.mutable_solver()->set_continued_from_t_s(continued_from_);
  write_deposit(dep, su_, n_frames, rec);
  write_stations(L_, su_, s, rec);
  mon_->write(rec);
  figures::PlanFigure plan;  // comparison.png of a 3D run
  plan.title = title;
  if (g.three_d) write_chute(L_, su_, s, plan, rec);
  sum.files = {"fields.h5", "fields.xmf", "figure.png", "run.json", "comparison.png"};
  if (face_) {  // a nest: its inflows and balance; the record as CSV
    write_nest(*face_, balance_, dep.volume, s.time(), su_.m.cells(), g.dx, *rec.mutable_nest());
    if (continued) rec.mutable_nest()->set_continued_from_s(continued_from_);
    sum.volume_error = rec.nest().volume_error_3d();
    rec.mutable_results()->set_volume_relative_error(sum.volume_error);
    write_face_csv(out_dir_ + "/nest_inflow.csv", *face_);
    sum.files.push_back("nest_inflow.csv");
  }
  sum.seconds_write = since(t2);

  write_timings(sum, fig_, su_.m.cells(), rec);
  for (const auto& f : sum.files) rec.add_outputs(f);
  rec.mutable_execution()->set_petsc_options(petsc_options());
  record_distribution(s, fig_.steps, rec);
  write_run_record(out_dir_ + "/run.json", rec);
  if (g.three_d) figures::write_plan_figure(out_dir_ + "/comparison.png", plan);
  else write_section_comparison(out_dir_ + "/comparison.png", title, L_, su_, s, dep, *mon_);
  return sum;
}

}  // namespace

std::unique_ptr<EngineRun> prepare_vof_lab(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt) {
  return std::make_unique<LabRun>(s, out_dir, opt);
}

}  // namespace runout::jobs
