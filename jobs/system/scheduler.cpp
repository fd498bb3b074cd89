#include "jobs/system/scheduler.hpp"

#include <fcntl.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <csignal>
#include <optional>
#include <random>
#include <thread>

#include "jobs/system/state_dir.hpp"
#include "jobs/system/slurm.hpp"
#include "jobs/system/worker.hpp"
#include "runout/v1/worker.pb.h"

namespace fs = std::filesystem;

namespace runout::jobs {

Scheduler::Scheduler(JobStore& store, SchedulerConfig cfg) : store_(store), cfg_(std::move(cfg)) {
  if (cfg_.workers < 1) cfg_.workers = 1;
  if (cfg_.threads_per_run <= 0) cfg_.threads_per_run = std::max(1, omp_get_num_procs() / cfg_.workers);
  if (cfg_.worker_exe.empty()) cfg_.worker_exe = self_executable();
  if (cfg_.max_crashes < 1) cfg_.max_crashes = 1;
  fs::create_directories(fs::path(cfg_.state_dir) / "results");
  fs::create_directories(fs::path(cfg_.state_dir) / "logs");
  fs::create_directories(fs::path(cfg_.state_dir) / "checkpoints");
  if (cfg_.slurm) {
    SlurmConfig sc = *cfg_.slurm;
    std::error_code ec;
    if (sc.worker_exe.empty()) sc.worker_exe = fs::read_symlink("/proc/self/exe", ec).string();  // as the compute nodes see it
    if (sc.job_name.empty()) {  // one name per state directory, kept in it: a restarted server finds what its predecessor left
      const fs::path name_file = fs::path(cfg_.state_dir) / "slurm" / "job-name";
      std::ifstream in(name_file);
      std::getline(in, sc.job_name);
      if (sc.job_name.rfind("runout-", 0) != 0) {
        std::random_device rd;
        char b[24];
        std::snprintf(b, sizeof b, "%08x%08x", unsigned(rd()), unsigned(rd()));
        sc.job_name = std::string("runout-") + b;
        fs::create_directories(name_file.parent_path(), ec);
        std::ofstream(name_file) << sc.job_name << "\n";
      }
    }
    slurm_ = std::make_unique<SlurmSubmitter>((fs::path(cfg_.state_dir) / "slurm").string(), sc);
  }
}

Scheduler::~Scheduler() { stop(); }

void Scheduler::log(const std::string& line) const {
  if (cfg_.log) cfg_.log(line);
}

void Scheduler::start() {
  // Tasks a server killed outright left on the cluster: cancelled (they end at their step, with a
  // checkpoint), their jobs queued again below.
  if (slurm_) slurm_->cancel_all();
  std::vector<JobStore::Change> changed;
  const int n = store_.requeue_running(
      "the server went down during the run; queued to run again (from its last checkpoint where it has one)", &changed);
  for (const auto& c : changed) append_job_log(c.id, state_name(c.state) + ": " + c.reason);
  if (n) log("queued again " + std::to_string(n) + " job(s) left running by the previous server process");
  // Work in progress of a dead process is worthless: its jobs run again.
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(cfg_.state_dir) / "results", ec))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) fs::remove_all(e.path(), ec);
  apply_retention();
  stopping_ = false;
  for (int k = 0; k < cfg_.workers; ++k) threads_.emplace_back([this, k] { worker_loop(k); });
}

void Scheduler::stop() {
  {
    std::lock_guard lk(mu_);
    stopping_ = true;
  }
  work_cv_.notify_all();
  change_cv_.notify_all();
  for (auto& t : threads_)
    if (t.joinable()) t.join();
  threads_.clear();
}

void Scheduler::notify() {
  {
    std::lock_guard lk(mu_);
    ++work_seq_;
  }
  work_cv_.notify_all();  // an ensemble queues many jobs at once: every idle worker claims one
}

bool Scheduler::cancel_running(const std::string& id) {
  std::lock_guard lk(mu_);
  cancel_.insert(id);  // also when the worker has claimed the job but not yet started it
  const auto it = live_.find(id);
  return it != live_.end() && it->second.running;
}

Scheduler::Live Scheduler::live(const std::string& id) const {
  std::lock_guard lk(mu_);
  Live l;
  if (const auto it = live_.find(id); it != live_.end()) l = it->second;
  if (const auto v = versions_.find(id); v != versions_.end()) l.version = std::max(l.version, v->second);
  return l;
}

void Scheduler::wait_change(const std::string& id, std::uint64_t version, std::chrono::milliseconds timeout) const {
  std::unique_lock lk(mu_);
  change_cv_.wait_for(lk, timeout, [&] {
    const auto v = versions_.find(id);
    return stopping_.load() || (v != versions_.end() && v->second > version);
  });
}

void Scheduler::touch(const std::string& id) {
  {
    std::lock_guard lk(mu_);
    versions_[id] = ++counter_;
  }
  change_cv_.notify_all();
}

void Scheduler::worker_loop(int index) {
  omp_set_num_threads(cfg_.threads_per_run);
  (void)index;
  while (!stopping_) {
    std::uint64_t seen = 0;
    {
      std::lock_guard lk(mu_);
      seen = work_seq_;
    }
    std::optional<StoredJob> job;
    try {
      job = store_.claim_next();
    } catch (const std::exception& e) {
      log(std::string("worker: the job store failed: ") + e.what());
    }
    if (!job) {
      std::unique_lock lk(mu_);
      // Woken by notify() (also one that came during the claim above) or stop().
      work_cv_.wait_for(lk, std::chrono::seconds(2), [&] { return stopping_.load() || work_seq_ != seen; });
      const bool due = std::chrono::steady_clock::now() - last_retention_ > std::chrono::hours(1);
      lk.unlock();
      if (due) {
        try {
          apply_retention();
        } catch (const std::exception& e) {
          log(std::string("retention failed: ") + e.what());
        }
      }
      continue;
    }
    // Nothing may end this thread: a job that throws is recorded as failed (when the store can).
    const std::string id = job->job.id();
    try {
      run_job(std::move(*job));
    } catch (const std::exception& e) {
      log("job " + id + ": " + e.what());
      try {
        store_.transition(id, v1::FAILED, "the job system failed", e.what());
      } catch (...) {
      }
      {
        std::lock_guard lk(mu_);
        live_.erase(id);
        cancel_.erase(id);
      }
      touch(id);
    }
  }
}

bool Scheduler::on_progress(const std::string& id, const v1::Progress& pr) {
  bool go = true;
  {
    std::lock_guard lk(mu_);
    auto& l = live_[id];
    l.progress = pr;
    l.running = true;
    l.version = ++counter_;
    versions_[id] = counter_;
    go = !stopping_.load() && !cancel_.count(id);
  }
  change_cv_.notify_all();
  return go;
}

// One job's run on this server: its log, its paths and limits, and how it is recorded.
struct Scheduler::JobContext {
  Scheduler& s;
  StoredJob sj;
  std::string id, hash;
  std::ofstream logf;
  fs::path final_dir, tmp;
  std::string cp;
  double wall_limit = 0;
  std::int64_t mem_limit = 0;
  std::chrono::milliseconds grace{1000};

  JobContext(Scheduler& sched, StoredJob job) : s(sched), sj(std::move(job)), id(sj.job.id()), hash(sj.job.scenario_hash()) {
    logf.open(s.log_path(id), std::ios::app);
    final_dir = s.results_dir(hash);
    tmp = fs::path(final_dir.string() + ".tmp-" + id);
    cp = s.checkpoint_path(id);
    wall_limit = s.cfg_.max_job_wall_s;
    if (sj.scenario.limits().max_wall_s() > 0) wall_limit = std::min(wall_limit, sj.scenario.limits().max_wall_s());
    mem_limit = s.cfg_.max_job_memory_bytes;
    if (sj.scenario.limits().max_memory_bytes() > 0)
      mem_limit = mem_limit > 0 ? std::min(mem_limit, sj.scenario.limits().max_memory_bytes()) : sj.scenario.limits().max_memory_bytes();
    grace = std::chrono::milliseconds(std::int64_t(1000 * s.cfg_.stop_grace_s));
  }
  void say(const std::string& line) {
    logf << utc_now() << " " << line << "\n";
    logf.flush();
  }
  void finish(v1::JobState state, const std::string& reason, const std::string& error, std::int64_t bytes, bool crashed = false) {
    try {
      s.store_.transition(id, state, reason, error, bytes, crashed);
    } catch (const std::exception& e) {
      s.log("job " + id + ": recording '" + reason + "' failed: " + e.what());
    }
    say(state_name(state) + ": " + reason);  // (`runout serve --recover` reads these lines)
    if (!error.empty()) say("error: " + error);
    s.log("job " + id + ": " + state_name(state) + (error.empty() ? "" : " (" + error + ")"));
    {
      std::lock_guard lk(s.mu_);
      s.live_.erase(id);
      s.cancel_.erase(id);
    }
    s.touch(id);
    if (!sj.job.parent_id().empty()) s.touch(sj.job.parent_id());  // its ensemble's counts changed
  }
  void finish_and_forget(v1::JobState state, const std::string& reason, const std::string& error, std::int64_t bytes) {
    s.remove_checkpoint(id);
    finish(state, reason, error, bytes);
  }
};

// What one worker process of a job did.
struct Scheduler::Attempt {
  enum class Why { none, cancel, stop, wall, memory };
  Why why = Why::none;                    // why we ended it (none: it ended by itself)
  std::optional<v1::WorkerEvent> outcome;  // its outcome event, when it sent one
  WorkerExit exit;
  std::string start_error;  // it could not be started
  bool stuck = false;       // it did not end after SIGKILL: left behind (reaped by a thread of its own)
};

void Scheduler::run_job(StoredJob job) {
  JobContext jc(*this, std::move(job));
  const std::string& id = jc.id;
  const int ranks = std::max(1, jc.sj.scenario.ranks());
  // A job over MPI ranks takes one slot; its ranks share the slot's threads (at least one each).
  const int threads = std::max(1, cfg_.threads_per_run / ranks);
  jc.say("attempt " + std::to_string(jc.sj.job.attempts()) + ": started (scenario " + jc.hash.substr(0, 12) + ", " +
         (ranks > 1 ? std::to_string(ranks) + " MPI ranks of " : std::string()) + std::to_string(threads) + " threads)");
  log("job " + id + ": started");
  {
    std::lock_guard lk(mu_);
    live_[id] = Live{jc.sj.job.progress(), ++counter_, true};
    versions_[id] = counter_;
    if (!jc.sj.job.parent_id().empty()) versions_[jc.sj.job.parent_id()] = ++counter_;  // its ensemble's counts changed
  }
  change_cv_.notify_all();
  std::error_code ec;
  {
    std::unique_lock results_lk(results_mu_);  // not while retention removes results
    if (fs::exists(jc.final_dir / "run.json", ec)) {
      const auto bytes = folder_bytes(jc.final_dir.string());
      results_lk.unlock();
      jc.finish_and_forget(v1::SUCCEEDED, "an identical scenario was computed before: its results answer this job", "", bytes);
      return;
    }
  }
  fs::remove_all(jc.tmp, ec);
  bool cancelled_early = false;
  try {
    cancelled_early = store_.cancel_requested(id);
  } catch (const std::exception& e) {
    log("job " + id + ": the job store failed: " + e.what());
  }
  {
    std::lock_guard lk(mu_);
    cancelled_early = cancelled_early || cancel_.count(id) > 0;
  }
  if (cancelled_early) {
    jc.finish_and_forget(v1::CANCELLED, "cancelled by the client before the run started", "", 0);
    return;
  }
  // The task: every run keeps a checkpoint (and its frames so far) in checkpoints/ID.h5 while it
  // runs, so that a job interrupted by the server stopping, by its death or by a crash of its worker
  // continues from there.
  v1::WorkerTask task;
  if (!ensemble_task(jc, task)) return;
  task.set_job_id(id);
  *task.mutable_scenario() = jc.sj.scenario;
  task.set_out_dir(jc.tmp.string());
  task.set_threads(threads);
  task.set_ranks(ranks);
  task.set_progress_interval_s(0.25);
  task.set_checkpoint_path(jc.cp);
  task.set_checkpoint_interval_s(-1);  // a twentieth of the end time (the worker knows it, defaults filled in)
  if (cfg_.terrain_cache) task.set_terrain_cache_dir((fs::path(cfg_.state_dir) / "cache" / "terrain").string());
  if (fs::exists(jc.cp, ec)) {
    task.set_restart_path(jc.cp);
    jc.say("continuing from its checkpoint");
  }
  for (int round = 0;; ++round) {
    fs::remove_all(jc.tmp, ec);
    fs::create_directories(jc.tmp, ec);
    const Attempt a = supervise(jc, task);
    if (!conclude(jc, task, a, round)) return;
  }
}

bool Scheduler::ensemble_task(JobContext& jc, v1::WorkerTask& task) {
  const auto members = store_.members(jc.id);
  if (members.empty()) return true;  // a job of its own
  int failed = 0, cancelled = 0;
  const StoredJob* first_failed = nullptr;
  for (const auto& m : members) {
    if (m.job.state() == v1::FAILED && !failed++) first_failed = &m;
    if (m.job.state() == v1::CANCELLED) ++cancelled;
  }
  if (failed) {
    jc.finish_and_forget(v1::FAILED, "a member failed",
                         std::to_string(failed) + " of " + std::to_string(members.size()) + " members failed; member " +
                             std::to_string(first_failed->job.member_index()) + " (job " + first_failed->job.id() +
                             "): " + first_failed->job.error(),
                         0);
    return false;
  }
  if (cancelled) {
    jc.finish_and_forget(v1::CANCELLED, std::to_string(cancelled) + " of " + std::to_string(members.size()) + " members were cancelled", "", 0);
    return false;
  }
  std::error_code ec;
  for (const auto& m : members) {
    const std::string dir = results_dir(m.job.scenario_hash());
    if (m.results_removed || !fs::exists(fs::path(dir) / "run.json", ec)) {
      jc.finish_and_forget(v1::FAILED, "a member's results are gone",
                           "the results of member " + std::to_string(m.job.member_index()) + " (job " + m.job.id() +
                               ") were removed (retention) before the aggregate; submit the ensemble again",
                           0);
      return false;
    }
    task.add_member_dirs(dir);
    task.add_member_hashes(m.job.scenario_hash());
  }
  jc.say("aggregating " + std::to_string(members.size()) + " members");
  return true;
}

Scheduler::Attempt Scheduler::supervise(JobContext& jc, const v1::WorkerTask& task) {
  using Why = Attempt::Why;
  const std::string& id = jc.id;
  Attempt a;
  try {
    std::unique_ptr<Execution> run;
    if (slurm_)
      run = std::make_unique<SlurmStep>(*slurm_, task, log_path(id));
    else
      run = std::make_unique<WorkerProcess>(cfg_.worker_exe, task, log_path(id), cfg_.mpi_launcher);
    Execution& w = *run;
    jc.say(w.where());
    const auto t0 = std::chrono::steady_clock::now();
    auto last_check = t0, kill_at = t0, last_saved = t0;
    std::optional<std::chrono::steady_clock::time_point> running;  // the wall time counts once it runs (a cluster queues first)
    for (;;) {
      // Every event the worker wrote is read, also after its output closed (the outcome may be
      // the last of several events that arrived at once).
      auto ev = w.next_event(std::chrono::milliseconds(100));
      if (!ev && w.output_closed()) break;
      const auto now = std::chrono::steady_clock::now();
      if (ev && ev->has_progress()) {
        if (!on_progress(id, ev->progress()) && a.why == Why::none) {
          std::lock_guard lk(mu_);
          a.why = cancel_.count(id) ? Why::cancel : Why::stop;
        }
        if (now - last_saved > std::chrono::seconds(1)) {
          last_saved = now;
          const auto& p = ev->progress();
          try {
            store_.save_progress(id, p);
          } catch (...) {
          }
          char b[200];
          std::snprintf(b, sizeof b, "t = %.3f s, dt = %.4g s, volume = %.6g m3, max speed = %.2f m/s, active = %.1f %%",
                        p.simulated_s(), p.dt_s(), p.volume_m3(), p.max_speed_m_s(), 100 * p.active_fraction());
          jc.say(b);
        }
      } else if (ev) {
        a.outcome = ev;
      }
      if (now - last_check > std::chrono::milliseconds(500)) {
        last_check = now;
        if (a.why == Why::none) {
          bool cancel = false;
          try {
            cancel = store_.cancel_requested(id);
          } catch (...) {
          }
          std::lock_guard lk(mu_);
          if (cancel) cancel_.insert(id);
        }
        if (!running && w.started()) running = now;
        if (a.why == Why::none && running && std::chrono::duration<double>(now - *running).count() > jc.wall_limit) a.why = Why::wall;
        if (a.why == Why::none && jc.mem_limit > 0 && w.resident_bytes() > jc.mem_limit) {
          a.why = Why::memory;
          w.signal(SIGKILL);  // memory is not given time
        }
      }
      {
        std::lock_guard lk(mu_);
        if (a.why == Why::none && cancel_.count(id)) a.why = Why::cancel;
        if (a.why == Why::none && stopping_) a.why = Why::stop;
      }
      if (a.why != Why::none && kill_at == t0) {
        w.signal(SIGTERM);  // ends at the end of its step (a stop keeps a checkpoint)
        kill_at = now + jc.grace;
      } else if (a.why != Why::none && now > kill_at) {
        w.signal(SIGKILL);
        // Local workers only: a Slurm step ends by the cluster's own kill timeout (KillWait).
        if (!slurm_ && now > kill_at + std::chrono::milliseconds(std::int64_t(1000 * cfg_.stuck_after_kill_s))) {
          a.stuck = true;
          break;
        }
      }
    }
    if (a.stuck) {
      leave_behind(jc, std::move(run), a);
      return a;
    }
    auto e = w.wait(jc.grace + std::chrono::seconds(5));
    if (!e) {
      w.signal(SIGKILL);
      e = w.wait(std::chrono::hours(1));
    }
    a.exit = *e;
  } catch (const std::exception& e) {
    a.start_error = e.what();
  }
  return a;
}

// A worker process that has not ended after SIGKILL (Attempt::stuck) cannot end yet: its job ends
// now, and a thread of its own reaps the process whenever it ends.
void Scheduler::leave_behind(JobContext& jc, std::unique_ptr<Execution> run, Attempt& a) {
  if (const auto e = run->wait(std::chrono::milliseconds(0))) {
    a.exit = *e;
  } else {
    a.exit.signal = SIGKILL;
    a.exit.signal_ours = true;
    std::thread([left = std::move(run)]() mutable { left.reset(); }).detach();
  }
  char b[40];
  std::snprintf(b, sizeof b, "%g", cfg_.stuck_after_kill_s);
  jc.say(std::string("worker process did not end within ") + b +
         " s of SIGKILL (stuck in uninterruptible I/O, or its output held open by a process it started): left behind, its slot "
         "released");
  log("job " + jc.id + ": its worker process did not end after SIGKILL; left behind, its slot released");
}

bool Scheduler::conclude(JobContext& jc, v1::WorkerTask& task, const Attempt& a, int round) {
  using Why = Attempt::Why;
  std::error_code ec;
  if (!a.start_error.empty()) {
    fs::remove_all(jc.tmp, ec);
    if (slurm_ && jc.sj.crashes + 1 < cfg_.max_crashes) {  // the cluster may refuse for a while (limits, a restart)
      std::this_thread::sleep_for(std::chrono::seconds(5));
      jc.finish(v1::QUEUED, "the cluster did not take the task (" + a.start_error + "); queued to run again", "", 0, true);
      return false;
    }
    jc.finish_and_forget(v1::FAILED, "the worker process could not be started", a.start_error, 0);
    return false;
  }
  const std::string exit_text = a.exit.describe();
  if (!(a.exit.exited && a.exit.code == 0)) jc.say("worker process ended by " + exit_text);
  Why why = a.why;
  {
    std::lock_guard lk(mu_);  // a stop that came while the worker was ending
    if (why == Why::none && stopping_) why = Why::stop;
  }
  const auto& outcome = a.outcome;
  if (why == Why::cancel && !(outcome && outcome->has_done())) {
    fs::remove_all(jc.tmp, ec);
    const double t = outcome && outcome->has_interrupted() ? outcome->interrupted().simulated_s() : 0.0;
    jc.finish_and_forget(v1::CANCELLED, "cancelled by the client at t = " + std::to_string(t) + " s; no results kept", "", 0);
    return false;
  }
  if (outcome && outcome->has_done()) {
    std::unique_lock results_lk(results_mu_);  // not while retention removes results
    fs::rename(jc.tmp, jc.final_dir, ec);
    if (ec) {
      // Another job with the same hash finished first: its (identical) results stand.
      fs::remove_all(jc.tmp, ec);
      if (!fs::exists(jc.final_dir / "run.json", ec)) {
        jc.finish_and_forget(v1::FAILED, "the run failed", "cannot move the results into place", 0);
        return false;
      }
    }
    const auto bytes = folder_bytes(jc.final_dir.string());
    results_lk.unlock();
    jc.say("finished: " + outcome->done().summary());
    jc.finish_and_forget(v1::SUCCEEDED, "completed", "", bytes);
    return false;
  }
  fs::remove_all(jc.tmp, ec);
  if (why == Why::wall || why == Why::memory) {
    char b[200];
    if (why == Why::wall)
      std::snprintf(b, sizeof b, "the run exceeded its wall-time limit of %.0f s and was stopped", jc.wall_limit);
    else
      std::snprintf(b, sizeof b, "the run exceeded its memory limit of %.0f MiB and was stopped", double(jc.mem_limit) / (1 << 20));
    jc.finish_and_forget(v1::FAILED, "stopped by a limit", b, 0);
    return false;
  }
  if (why == Why::stop || (outcome && outcome->has_interrupted())) {
    const bool cp_now = outcome && outcome->has_interrupted() && outcome->interrupted().checkpoint_written();
    const bool cp_any = cp_now || fs::exists(jc.cp, ec);
    jc.finish(v1::QUEUED, std::string("interrupted by the server stopping") +
                              (cp_now ? " at t = " + std::to_string(outcome->interrupted().simulated_s()) + " s" : "") +
                              "; queued to " + (cp_any ? "continue from its checkpoint" : "run again from the start"),
              "", 0);
    return false;
  }
  if (outcome && outcome->has_failed()) {
    const auto& f = outcome->failed();
    if (!task.restart_path().empty() && f.bad_input() && f.error().find("checkpoint") != std::string::npos && round == 0) {
      // A checkpoint this build cannot continue (damaged, or from another build): from the start.
      jc.say("its checkpoint cannot be continued (" + client_message(f.error(), cfg_.state_dir, cfg_.data_roots) +
             "); running again from the start");
      log("job " + jc.id + ": checkpoint refused (" + f.error() + "); running from the start");
      remove_checkpoint(jc.id);
      task.clear_restart_path();
      return true;
    }
    jc.finish_and_forget(v1::FAILED, "the run failed", client_message(f.error(), cfg_.state_dir, cfg_.data_roots), 0);
    return false;
  }
  if (!a.exit.exited && (a.exit.signal == SIGTERM || a.exit.signal == SIGINT || a.exit.signal == SIGHUP)) {
    // Stopped from outside (an operator's signal to the worker): not the job's fault.
    jc.finish(v1::QUEUED, "its worker process was stopped from outside (" + exit_text + "); queued to run again", "", 0);
    return false;
  }
  // No outcome: the worker process died of a signal nobody sent, or exited without a word.
  const int crashes = jc.sj.crashes + 1;
  if (crashes >= cfg_.max_crashes) {
    remove_checkpoint(jc.id);
    jc.finish(v1::FAILED, "its worker process crashed",
              "the job's worker process crashed (" + exit_text + ") in " + std::to_string(crashes) + " attempts", 0, true);
    return false;
  }
  jc.finish(v1::QUEUED,
            "its worker process crashed (" + exit_text + "); queued to run again (" + std::to_string(crashes) + " of " +
                std::to_string(cfg_.max_crashes) + " crashes allowed)",
            "", 0, true);
  return false;
}

}  // namespace runout::jobs
