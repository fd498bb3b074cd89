#include "jobs/drivers/worker_task.hpp"

#include <fcntl.h>
#include <omp.h>
#include <signal.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "jobs/drivers/ensemble_aggregate.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_support.hpp"
#include "jobs/ensemble/variations.hpp"
#include "jobs/scenario/scenario.hpp"
#include "runout/v1/worker.pb.h"
#include "terrain/terrain.hpp"

namespace runout::jobs {

namespace {

// A failed run's error with the disk's state when the disk that holds its results (or its
// checkpoint) is full: the libraries that wrote say only "Input/output error" or "writing ... failed".
std::string with_disk_state(const std::string& error, const std::vector<std::string>& paths) {
  if (error.find("disk is full") != std::string::npos) return error;
  for (const auto& p : paths) {
    struct statvfs v {};
    if (p.empty() || ::statvfs(p.c_str(), &v) != 0) continue;
    const double free_bytes = double(v.f_bavail) * double(v.f_frsize);
    if (free_bytes < kFullDiskBytes)
      return error + " (the disk is full: " + std::to_string(std::int64_t(free_bytes) >> 10) + " KiB free where the results are written)";
  }
  return error;
}

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop(int) { g_stop = 1; }

bool write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += w;
    n -= std::size_t(w);
  }
  return true;
}

// One event: 4 bytes of length (little endian), then the message.
bool send_event(int fd, const v1::WorkerEvent& ev) {
  std::string body;
  ev.SerializeToString(&body);
  const auto n = std::uint32_t(body.size());
  const char head[4] = {char(n & 255), char((n >> 8) & 255), char((n >> 16) & 255), char((n >> 24) & 255)};
  return write_all(fd, head, 4) && write_all(fd, body.data(), body.size());
}

// An ensemble's job: its members have run; aggregate their results (the members are expanded
// again from the scenario, which gives them in the same order as at the submission).
int aggregate(const ResolvedScenario& r, const v1::WorkerTask& task, int events) {
  const auto expanded = ensemble::expand(r.scenario);
  if (task.member_dirs_size() == 0)
    throw std::invalid_argument("an ensemble (variations or zoning) runs as its members: submit it to the job system (runout run or the service)");
  if (int(expanded.size()) != task.member_dirs_size() || task.member_hashes_size() != task.member_dirs_size())
    throw std::runtime_error("the ensemble has " + std::to_string(expanded.size()) + " members, the task names " +
                             std::to_string(task.member_dirs_size()));
  std::vector<MemberResults> members;
  for (std::size_t k = 0; k < expanded.size(); ++k)
    members.push_back({expanded[k], task.member_hashes(int(k)), task.member_dirs(int(k))});
  v1::WorkerEvent ev;
  try {
    const auto rec = aggregate_ensemble(r, members, task.out_dir(), [](int, int) { return g_stop == 0; });
    auto* d = ev.mutable_done();
    d->set_stop("aggregated");
    char b[300];
    std::snprintf(b, sizeof b, "aggregated %d members into %d files in %.2f s", int(members.size()), rec.outputs_size(),
                  rec.aggregate_seconds());
    d->set_summary(b);
  } catch (const AggregateStopped&) {
    ev.mutable_interrupted()->set_checkpoint_written(false);
  }
  return send_event(events, ev) ? 0 : 3;
}

std::string read_all(int fd) {
  std::string in;
  char b[65536];
  for (;;) {
    const ssize_t n = ::read(fd, b, sizeof b);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    in.append(b, std::size_t(n));
  }
  return in;
}

// The task's run, its progress and its one outcome on `events`. `failed` tells whether the outcome
// is a failure (under a launcher, the ranks are then ended together).
int run_task(const v1::WorkerTask& task, int events, bool& failed_run) {
  auto failed = [&](const std::string& error, bool bad_input) {
    failed_run = true;
    v1::WorkerEvent ev;
    const std::string ckpt = task.checkpoint_path().empty() ? "" : std::filesystem::path(task.checkpoint_path()).parent_path().string();
    ev.mutable_failed()->set_error(bad_input ? error : with_disk_state(error, {task.out_dir(), ckpt}));
    ev.mutable_failed()->set_bad_input(bad_input);
    return send_event(events, ev) ? 0 : 3;
  };
  if (task.threads() > 0) omp_set_num_threads(task.threads());
  try {
    const ResolvedScenario r = resolve_scenario(task.scenario(), "/");
    if (ensemble::is_ensemble(r.scenario)) return aggregate(r, task, events);
    RunOptions opt;
    opt.progress_every = 1;  // the stop flag is seen after every step
    opt.checkpoint_path = task.checkpoint_path();
    opt.restart_path = task.restart_path();
    opt.terrain_cache_dir = task.terrain_cache_dir();
    const double t_end = r.end_time_s();
    opt.checkpoint_interval_s = task.checkpoint_interval_s() < 0 ? t_end / 20 : task.checkpoint_interval_s();
    const double every = task.progress_interval_s() > 0 ? task.progress_interval_s() : 0.5;
    const auto wall0 = std::chrono::steady_clock::now();
    auto last = wall0 - std::chrono::hours(1);
    bool event_failed = false;
    opt.progress = [&](const engine::Progress& p) {
      if (task.validate_only()) return false;  // prepared and one step taken: every input check has run
      const auto now = std::chrono::steady_clock::now();
      if (std::chrono::duration<double>(now - last).count() >= every) {
        last = now;
        v1::WorkerEvent ev;
        auto* pr = ev.mutable_progress();
        pr->set_simulated_s(p.t);
        pr->set_dt_s(p.dt);
        pr->set_volume_m3(p.mass);
        pr->set_max_speed_m_s(p.max_speed);
        pr->set_active_fraction(p.active_fraction);
        pr->set_end_time_s(t_end);
        pr->set_steps(p.step);
        const double wall = std::chrono::duration<double>(now - wall0).count();
        pr->set_seconds_left(p.t > 0 ? wall * (t_end - p.t) / p.t : 0.0);
        event_failed = event_failed || !send_event(events, ev);
      }
      return g_stop == 0 && !event_failed;
    };
    const RunSummary sum = run_scenario(r, task.out_dir(), opt);
    v1::WorkerEvent ev;
    if (sum.stop == "cancelled" && !task.validate_only()) {
      ev.mutable_interrupted()->set_simulated_s(sum.t);
      // Whether a checkpoint lies there now: a nested run stopped in its depth-averaged part has none.
      std::error_code ec;
      ev.mutable_interrupted()->set_checkpoint_written(!task.checkpoint_path().empty() && std::filesystem::exists(task.checkpoint_path(), ec));
    } else {
      auto* d = ev.mutable_done();
      d->set_steps(sum.steps);
      d->set_simulated_s(sum.t);
      d->set_stop(task.validate_only() ? "validated" : sum.stop);
      char b[300];
      std::snprintf(b, sizeof b, "%ld steps to t = %.3f s (stop: %s), affected area %.0f m2, %s, max speed %.1f m/s", sum.steps,
                    sum.t, sum.stop.c_str(), sum.affected_area_m2, runout_phrase(sum).c_str(), sum.max_speed);
      d->set_summary(b);
    }
    return send_event(events, ev) ? 0 : 3;
  } catch (const ScenarioError& e) {
    return failed(e.what(), true);
  } catch (const terrain::TerrainError& e) {
    return failed(e.what(), true);
  } catch (const std::invalid_argument& e) {
    return failed(e.what(), true);
  } catch (const std::exception& e) {
    return failed(e.what(), false);
  }
}

// A rank other than 0 of a task split over MPI ranks: it takes its part of the 3D run's steps and
// runs the same set-up and outputs into a private folder, which it removes; it writes no events
// (rank 0 speaks for the run) and no checkpoint of the task's (rank 0 writes it).
int run_other_rank(v1::WorkerTask task, int rank) {
  const RankScratch scratch(rank);
  if (!scratch.error().empty()) {
    std::fprintf(stderr, "runout worker (rank %d): %s\n", rank, scratch.error().c_str());
    return 4;
  }
  task.set_out_dir(scratch.out_dir());
  if (!task.checkpoint_path().empty()) task.set_checkpoint_path(scratch.checkpoint_path());
  const int quiet = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
  bool failed_run = false;
  const int rc = run_task(task, quiet, failed_run);
  if (quiet >= 0) ::close(quiet);
  return rc != 0 ? rc : failed_run ? 1 : 0;
}

}  // namespace

int worker_main(int in_fd, int out_fd) {
  // Under an MPI launcher (the task's ranks: mpirun -n N, srun with N tasks) the worker runs N
  // times; rank 0 reads the task and shares it, speaks for the run and writes its results.
  const LaunchRanks launch = launch_ranks();
  // Stray prints of libraries go to the log (standard error), never into the event stream.
  const int events = dup(out_fd);
  if (events < 0) return 3;
  dup2(2, out_fd);
  std::signal(SIGTERM, on_stop);
  std::signal(SIGINT, on_stop);
  // A stop under mpirun: mpirun forwards SIGUSR1 to every rank, while it answers SIGTERM by
  // killing them all within about two seconds (no time for the checkpoint).
  std::signal(SIGUSR1, on_stop);
  std::signal(SIGPIPE, SIG_IGN);
  std::signal(SIGXFSZ, SIG_IGN);  // a file-size limit makes writes fail (and the run report it), not the process die

  std::string in = launch.rank == 0 ? read_all(in_fd) : std::string();
  if (launch.size > 1) in = share_from_rank0(in);
  v1::WorkerTask task;
  if (!task.ParseFromString(in)) {
    if (launch.rank > 0) return finish_worker_ranks(4);
    v1::WorkerEvent ev;
    ev.mutable_failed()->set_error("the worker received an unreadable task");
    const int rc = send_event(events, ev) ? 0 : 3;
    return launch.size > 1 ? finish_worker_ranks(1) : rc;
  }
  if (launch.rank > 0) return finish_worker_ranks(run_other_rank(task, launch.rank));
  bool failed_run = false;
  const int rc = run_task(task, events, failed_run);
  if (launch.size == 1) return finish_worker_ranks(rc);  // (PETSc finalised, MPI with it, when a 3D run started them)
  ::close(events);  // the outcome is out before the ranks end
  return finish_worker_ranks(rc != 0 ? rc : failed_run ? 1 : 0);
}

}  // namespace runout::jobs
