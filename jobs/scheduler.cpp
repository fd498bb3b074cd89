#include "jobs/scheduler.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>

#include "jobs/run.hpp"
#include "jobs/scenario.hpp"

namespace fs = std::filesystem;

namespace runout::jobs {

namespace {

std::int64_t folder_bytes(const fs::path& p) {
  std::int64_t n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(p, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) n += std::int64_t(it->file_size(ec));
  return n;
}

// Seconds since the epoch of "YYYY-MM-DDTHH:MM:SS(.mmm)Z"; 0 when unreadable.
double epoch_of(const std::string& utc) {
  std::tm tm{};
  if (std::sscanf(utc.c_str(), "%d-%d-%dT%d:%d:%d", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min,
                  &tm.tm_sec) != 6)
    return 0;
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return double(timegm(&tm));
}

}  // namespace

Scheduler::Scheduler(JobStore& store, SchedulerConfig cfg) : store_(store), cfg_(std::move(cfg)) {
  if (cfg_.workers < 1) cfg_.workers = 1;
  if (cfg_.threads_per_run <= 0) cfg_.threads_per_run = std::max(1, omp_get_num_procs() / cfg_.workers);
  fs::create_directories(fs::path(cfg_.state_dir) / "results");
  fs::create_directories(fs::path(cfg_.state_dir) / "logs");
  fs::create_directories(fs::path(cfg_.state_dir) / "checkpoints");
}

std::string Scheduler::checkpoint_path(const std::string& id) const {
  return (fs::path(cfg_.state_dir) / "checkpoints" / (id + ".h5")).string();
}

void Scheduler::remove_checkpoint(const std::string& id) const {
  std::error_code ec;
  fs::remove(checkpoint_path(id), ec);
  fs::remove(checkpoint_path(id) + ".fields.h5", ec);
  fs::remove(checkpoint_path(id) + ".part", ec);
}

Scheduler::~Scheduler() { stop(); }

void Scheduler::log(const std::string& line) const {
  if (cfg_.log) cfg_.log(line);
}

std::string Scheduler::results_dir(const std::string& hash) const {
  return (fs::path(cfg_.state_dir) / "results" / hash).string();
}

std::string Scheduler::log_path(const std::string& id) const {
  return (fs::path(cfg_.state_dir) / "logs" / (id + ".log")).string();
}

void Scheduler::start() {
  const int n = store_.requeue_running(
      "the server stopped during the run; queued to run again (a VOF run continues from its last checkpoint)");
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
  work_cv_.notify_one();
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

void Scheduler::remove_orphan_checkpoints() {
  // A checkpoint is kept only for a job that will run again: one cancelled while it waited in the
  // queue, or ended by the store at a restart (cancel flag, too many attempts), leaves its own.
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(cfg_.state_dir) / "checkpoints", ec)) {
    std::string id = e.path().filename().string();
    id = id.substr(0, id.find('.'));
    std::optional<StoredJob> job;
    try {
      job = store_.get(id);
    } catch (...) {
      continue;
    }
    const bool live = job && (job->job.state() == v1::QUEUED || job->job.state() == v1::RUNNING);
    if (!live) {
      fs::remove(e.path(), ec);
      log("removed the checkpoint file " + e.path().filename().string() + " of a job that will not run again");
    }
  }
}

void Scheduler::apply_retention() {
  std::lock_guard once(retention_mu_);  // one pass at a time
  {
    std::lock_guard lk(mu_);
    last_retention_ = std::chrono::steady_clock::now();
  }
  remove_orphan_checkpoints();
  if (cfg_.retention_days <= 0 && cfg_.retention_max_bytes <= 0) return;
  auto finished = store_.finished_results();  // oldest first
  const double now = double(std::time(nullptr));
  std::int64_t total = 0;
  for (const auto& f : finished) total += f.bytes;
  for (const auto& f : finished) {
    const bool old = cfg_.retention_days > 0 && now - epoch_of(f.updated) > cfg_.retention_days * 86400.0;
    const bool over = cfg_.retention_max_bytes > 0 && total > cfg_.retention_max_bytes;
    if (!old && !over) continue;
    std::error_code ec;
    fs::remove_all(results_dir(f.hash), ec);
    total -= f.bytes;
    store_.mark_results_removed(f.hash, old ? "results removed by the retention policy (older than " +
                                                  std::to_string(cfg_.retention_days) + " days)"
                                            : "results removed by the retention policy (disk limit)");
    log("retention: removed results " + f.hash.substr(0, 12) + " (" + std::to_string(f.bytes) + " bytes)");
  }
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
      if (due) apply_retention();
      continue;
    }
    run_job(std::move(*job));
  }
}

void Scheduler::run_job(StoredJob sj) {
  const std::string id = sj.job.id(), hash = sj.job.scenario_hash();
  std::ofstream logf(log_path(id), std::ios::app);
  auto say = [&](const std::string& line) {
    logf << utc_now() << " " << line << "\n";
    logf.flush();
  };
  say("attempt " + std::to_string(sj.job.attempts()) + ": started (scenario " + hash.substr(0, 12) + ", " +
      std::to_string(cfg_.threads_per_run) + " threads)");
  log("job " + id + ": started");
  {
    std::lock_guard lk(mu_);
    live_[id] = Live{sj.job.progress(), ++counter_, true};
    versions_[id] = counter_;
  }
  change_cv_.notify_all();
  auto end_live = [&] {
    {
      std::lock_guard lk(mu_);
      live_.erase(id);
      cancel_.erase(id);
    }
    touch(id);
  };
  auto finish = [&](v1::JobState state, const std::string& reason, const std::string& error, std::int64_t bytes) {
    try {
      store_.transition(id, state, reason, error, bytes);
    } catch (const std::exception& e) {
      log("job " + id + ": recording '" + reason + "' failed: " + e.what());
    }
    say(state_name(state) + ": " + reason + (error.empty() ? "" : ": " + error));
    log("job " + id + ": " + state_name(state) + (error.empty() ? "" : " (" + error + ")"));
    end_live();
  };

  const fs::path final_dir = results_dir(hash);
  std::error_code ec;
  // VOF runs keep a checkpoint (and their frames so far) in checkpoints/ID.h5 while they run, so
  // that a job interrupted by the server stopping, or by its death, continues from there.
  const std::string cp = checkpoint_path(id);
  const bool had_checkpoint = fs::exists(cp, ec);
  auto finish_and_forget = [&](v1::JobState state, const std::string& reason, const std::string& error, std::int64_t bytes) {
    remove_checkpoint(id);
    finish(state, reason, error, bytes);
  };
  if (fs::exists(final_dir / "run.json", ec)) {
    finish_and_forget(v1::SUCCEEDED, "an identical scenario was computed before: its results answer this job", "",
                      folder_bytes(final_dir));
    return;
  }
  const fs::path tmp = fs::path(final_dir.string() + ".tmp-" + id);
  fs::remove_all(tmp, ec);
  bool cancelled_early = store_.cancel_requested(id);
  {
    std::lock_guard lk(mu_);
    cancelled_early = cancelled_early || cancel_.count(id) > 0;
  }
  if (cancelled_early) {
    finish_and_forget(v1::CANCELLED, "cancelled by the client before the run started", "", 0);
    return;
  }
  try {
    ResolvedScenario r = resolve_scenario(sj.scenario, "/");
    fs::create_directories(tmp);
    RunOptions opt;
    opt.progress_every = 20;
    if (r.vof) {
      opt.checkpoint_path = cp;
      opt.checkpoint_interval_s = sj.scenario.lab().end_time_s() / 20;
      if (had_checkpoint) {
        opt.restart_path = cp;
        say("continuing from its checkpoint");
      }
    }
    const auto wall0 = std::chrono::steady_clock::now();
    auto last_save = wall0;
    const double t_end = r.config.time.t_end;
    opt.progress = [&](const engine::Progress& p) {
      v1::Progress pr;
      pr.set_simulated_s(p.t);
      pr.set_dt_s(p.dt);
      pr.set_volume_m3(p.mass);
      pr.set_max_speed_m_s(p.max_speed);
      pr.set_active_fraction(p.active_fraction);
      pr.set_end_time_s(t_end);
      pr.set_steps(p.step);
      const auto now = std::chrono::steady_clock::now();
      const double wall = std::chrono::duration<double>(now - wall0).count();
      pr.set_seconds_left(p.t > 0 ? wall * (t_end - p.t) / p.t : 0.0);
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
      if (now - last_save > std::chrono::seconds(1)) {
        last_save = now;
        try {
          if (store_.cancel_requested(id)) {
            std::lock_guard lk(mu_);
            cancel_.insert(id);
            go = false;
          }
        } catch (...) {
        }
        try {
          store_.save_progress(id, pr);
        } catch (...) {
        }
        char b[200];
        std::snprintf(b, sizeof b, "t = %.2f s, dt = %.4f s, volume = %.6g m3, max speed = %.2f m/s, active = %.1f %%", p.t,
                      p.dt, p.mass, p.max_speed, 100 * p.active_fraction);
        say(b);
      }
      return go;
    };
    RunSummary sum;
    try {
      sum = run_scenario(r, tmp.string(), opt);
    } catch (const ScenarioError& e) {
      if (opt.restart_path.empty()) throw;
      // A checkpoint this build cannot continue (damaged, or from another build): from the start.
      say(std::string("its checkpoint cannot be continued (") + e.what() + "); running again from the start");
      log("job " + id + ": checkpoint refused (" + e.what() + "); running from the start");
      remove_checkpoint(id);
      fs::remove_all(tmp, ec);
      fs::create_directories(tmp);
      opt.restart_path.clear();
      sum = run_scenario(r, tmp.string(), opt);
    }
    if (sum.stop == "cancelled") {
      fs::remove_all(tmp, ec);
      bool by_client = false;
      {
        std::lock_guard lk(mu_);
        by_client = cancel_.count(id) > 0;
      }
      if (by_client)
        finish_and_forget(v1::CANCELLED, "cancelled by the client at t = " + std::to_string(sum.t) + " s; no results kept", "", 0);
      else if (r.vof)
        finish(v1::QUEUED, "interrupted by the server stopping at t = " + std::to_string(sum.t) +
                               " s; queued to continue from its checkpoint", "", 0);
      else
        finish(v1::QUEUED, "interrupted by the server stopping; queued to run again from the start", "", 0);
      return;
    }
    fs::rename(tmp, final_dir, ec);
    if (ec) {
      // Another job with the same hash finished first: its (identical) results stand.
      fs::remove_all(tmp, ec);
      if (!fs::exists(final_dir / "run.json")) throw std::runtime_error("cannot move the results into place");
    }
    char b[300];
    std::snprintf(b, sizeof b, "finished: %ld steps to t = %.1f s (stop: %s), affected area %.0f m2, runout %.0f m, max speed %.1f m/s",
                  sum.steps, sum.t, sum.stop.c_str(), sum.affected_area_m2, sum.runout_m, sum.max_speed);
    say(b);
    finish_and_forget(v1::SUCCEEDED, "completed", "", folder_bytes(final_dir));
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    finish_and_forget(v1::FAILED, "the run failed", e.what(), 0);
  }
}

}  // namespace runout::jobs
