// `runout run ENSEMBLE.json --out DIR`: an ensemble (a scenario with `variations`) on this machine,
// through the same job system as the service (jobs/system: store, scheduler, worker processes) in a
// local state directory. Members run side by side on every core, each in a worker process of its
// own; members computed before (by any ensemble or single run in the same state directory) answer
// from their results; an interrupted ensemble continues where it stopped when the command is run again.
#include "service/cli/run_ensemble.hpp"

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <thread>

#include "jobs/ensemble/variations.hpp"
#include "jobs/scenario/inputs.hpp"
#include "jobs/system/scheduler.hpp"
#include "jobs/system/state_dir.hpp"
#include "jobs/system/store.hpp"
#include "service/cli/commands.hpp"

namespace fs = std::filesystem;

namespace runout::cli {

std::string ensemble_progress(const v1::EnsembleCounts& c, bool bar) {
  std::string s;
  const int done = c.succeeded() + c.failed() + c.cancelled();
  if (bar) {
    constexpr int kWidth = 30;
    const int fill = c.total() > 0 ? done * kWidth / c.total() : 0;
    s = "[" + std::string(std::size_t(fill), '#') + std::string(std::size_t(kWidth - fill), '.') + "]  ";
  }
  char b[200];
  std::snprintf(b, sizeof b, "%d of %d members done, %d running, %d queued%s", done, c.total(), c.running(), c.queued(),
                c.failed() ? (", " + std::to_string(c.failed()) + " failed").c_str() : "");
  return s + b;
}

std::string default_state_dir() {
  if (const char* s = std::getenv("RUNOUT_STATE_DIR"); s && *s) return s;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return (fs::path(x) / "runout").string();
  if (const char* h = std::getenv("HOME"); h && *h) return (fs::path(h) / ".cache" / "runout").string();
  return (fs::temp_directory_path() / "runout").string();
}

namespace {

int fail(const std::string& m, int code) {
  std::cerr << "runout run: " << m << "\n";
  return code;
}

// Follows the ensemble's job until it ends (`job` its last state), with a progress line; stops the
// scheduler on Ctrl-C. Returns an exit code, or -1 when the job ended.
int follow(jobs::JobStore& store, jobs::Scheduler& sched, const std::string& id, const EnsembleRun& a, const std::string& state,
           std::optional<jobs::StoredJob>& job) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string last;
  for (;;) {
    job = store.get(id);
    if (!job) return fail("the ensemble's job " + id + " vanished from the store", kInternal);
    if (!a.quiet) {
      const std::string line = ensemble_progress(job->job.members(), a.tty);
      if (line != last || a.tty) {
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::fprintf(stderr, "%s%s  %.0f s%s", a.tty ? "\r" : "", line.c_str(), wall, a.tty ? "   " : "\n");
        std::fflush(stderr);
        last = line;
      }
    }
    if (jobs::is_final(job->job.state())) return -1;
    if (a.interrupted && a.interrupted()) {
      sched.stop();  // running members end at their step with a checkpoint, and are queued again
      const auto c = store.get(id)->job.members();
      if (!a.quiet && a.tty) std::fprintf(stderr, "\n");
      std::cerr << "runout run: interrupted: " << c.succeeded() << " of " << c.total()
                << " members done; the same command continues the ensemble (state in " << state << ")\n";
      return kCancelled;
    }
    sched.wait_change(id, 0, std::chrono::milliseconds(250));
    std::this_thread::sleep_for(std::chrono::milliseconds(a.tty ? 250 : 1000));
  }
}

// The aggregate (and, on request, each member's results) into the staged output. Returns an exit
// code, or -1.
int copy_results(jobs::JobStore& store, jobs::Scheduler& sched, const jobs::StoredJob& job, const EnsembleRun& a) {
  std::error_code ec;
  fs::copy(sched.results_dir(job.job.scenario_hash()), a.out_dir, fs::copy_options::recursive, ec);
  if (ec) return fail("cannot copy the aggregate into the output: " + ec.message(), kOutput);
  if (a.with_members) {
    for (const auto& m : store.members(job.job.id())) {
      const fs::path to = fs::path(a.out_dir) / "members" / ("member_" + std::to_string(m.job.member_index()));
      fs::create_directories(to, ec);
      fs::copy(sched.results_dir(m.job.scenario_hash()), to, fs::copy_options::recursive, ec);
      if (ec) return fail("cannot copy member " + std::to_string(m.job.member_index()) + "'s results: " + ec.message(), kOutput);
    }
  }
  return -1;
}

}  // namespace

int run_ensemble(const jobs::ResolvedScenario& r, const EnsembleRun& a, RunSummaryOut& summary) {
  // The members' worker processes resolve their scenarios from "/": the inputs absolute.
  jobs::ResolvedScenario e = r;
  jobs::absolute_inputs(e.scenario, r.source.empty() ? "." : fs::path(r.source).parent_path().string());
  jobs::ensemble::Plan plan;
  try {
    plan = jobs::ensemble::plan(e);
  } catch (const std::exception& e) {
    return fail(e.what(), kBadInput);
  }
  const std::string state = fs::absolute(a.state_dir.empty() ? default_state_dir() : a.state_dir).string();
  std::error_code ec;
  fs::create_directories(state, ec);
  if (ec) return fail("cannot create the state directory '" + state + "': " + ec.message(), kOutput);
  std::unique_ptr<jobs::StateLock> lock;
  try {
    lock = std::make_unique<jobs::StateLock>(state);
    jobs::check_store(state);
  } catch (const std::exception& e) {
    return fail(std::string(e.what()) + " (--state-dir chooses another)", kService);
  }
  jobs::JobStore store((fs::path(state) / "jobs.db").string());
  jobs::SchedulerConfig cfg;
  cfg.state_dir = state;
  const int cores = a.workers > 0 ? a.workers : std::max(1, omp_get_num_procs());
  // More members than cores: one thread each, side by side; fewer: the cores shared among them.
  cfg.workers = std::max(1, std::min<int>(cores, int(plan.members.size())));
  cfg.threads_per_run = std::max(1, cores / cfg.workers);
  cfg.terrain_cache = a.terrain_cache;
  cfg.max_job_wall_s = 1e12;  // a local run has no wall limit (the service's is an operator's choice)
  cfg.stop_grace_s = 10;      // Ctrl-C: members end at their step with a checkpoint; a stuck one is killed after this
  jobs::Scheduler sched(store, cfg);
  std::vector<jobs::JobStore::NewMember> members;
  for (const auto& m : plan.members) members.push_back({m.member.index, m.hash, m.member.scenario});
  jobs::SubmitOutcome sub;
  try {
    sub = store.submit_ensemble("local", plan.hash, "", e.scenario, members, INT_MAX);
    if (sub.created) {
      sched.write_record(sub.job);
      for (const auto& m : store.members(sub.job.job.id())) sched.write_record(m);
    }
  } catch (const std::exception& e) {
    return fail(std::string("the job store failed: ") + e.what(), kInternal);
  }
  const std::string id = sub.job.job.id();
  if (!a.quiet)
    std::fprintf(stderr, "ensemble  %zu members (%s), job %s in %s; %d at a time, %d thread(s) each\n", plan.members.size(),
                 sub.created ? "queued" : "continuing the ensemble submitted before", id.c_str(), state.c_str(), cfg.workers,
                 cfg.threads_per_run);
  const auto t0 = std::chrono::steady_clock::now();
  sched.start();
  sched.notify();
  std::optional<jobs::StoredJob> job;
  if (const int rc = follow(store, sched, id, a, state, job); rc >= 0) return rc;
  if (!a.quiet && a.tty) std::fprintf(stderr, "\n");
  sched.stop();
  if (job->job.state() != v1::SUCCEEDED) {
    return fail("the ensemble " + jobs::state_name(job->job.state()) + (job->job.error().empty() ? "" : ": " + job->job.error()) +
                    " (the members' logs: " + (fs::path(state) / "logs").string() + ")",
                job->job.state() == v1::CANCELLED ? kCancelled : kFailed);
  }
  if (const int rc = copy_results(store, sched, *job, a); rc >= 0) return rc;
  summary.members = int(plan.members.size());
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary.state_dir = state;
  summary.job = id;
  return kOk;
}

}  // namespace runout::cli
