// The fault-injection suite (ctest label `reliability`), faults of the process and the machine:
// kills and stops during jobs, two servers, a damaged store, tokens, a full disk, crashing workers,
// limits, cancel and stop latency, a replaced program file. Each test starts its own `runout serve`
// on loopback and stops it by its pid, and prints a `reliability:` line with its figures.
#include "jobs/system/scheduler.hpp"
#include "tests/support/reliability_helpers.hpp"

using namespace runout::test_support::reliability;

// kill -9 and SIGTERM of the server at random moments while depth-averaged and VOF jobs run: every
// job finishes once, none is lost or failed, and each result is bitwise the uninterrupted run's.
TEST(Reliability, KillsAndStopsDuringJobsLoseNothingAndChangeNothing) {
  TempDir d;
  struct Case {
    std::string name;
    v1::Scenario s;
  };
  std::vector<Case> cases;
  for (double phi : {14.5, 15.0, 16.0}) cases.push_back({"arelen-" + std::to_string(int(phi * 10)), arelen(phi)});
  {
    auto ts = arelen(15.5);
    ts.mutable_outputs()->set_timeseries_interval_s(20);
    cases.push_back({"arelen-frames", ts});
  }
  cases.push_back({"collapse", coarse_collapse()});

  std::mt19937 rng(20261203);
  const fs::path state = d.p / "state";
  const std::vector<std::string> args = {"--data-root", kScenarios, "--workers", "2", "--threads-per-run", "1"};
  std::map<std::string, std::string> ids;  // request id -> job id
  int kills = 0, terms = 0, retries = 0, hits = 0;
  auto submit_all = [&](service::Client& c) {
    for (const auto& k : cases) {
      std::string id;
      if (code_of([&] { id = c.submit(k.s, "rel-" + k.name).id(); }) != 0) {
        ++retries;
        continue;
      }
      if (ids.count(k.name)) {
        EXPECT_EQ(ids[k.name], id) << "a retry of " << k.name << " got another job";
      }
      ids[k.name] = id;
    }
  };
  {
    auto srv = std::make_unique<ServerProcess>(state, args);
    ASSERT_TRUE(srv->running()) << srv->errors();
    {
      service::Client c(client_options(srv->address(), ""));
      submit_all(c);
    }
    for (int round = 0; round < 6; ++round) {
      std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(700, 2500)(rng)));
      {  // did this kill hit a job while it ran (past its first step)?
        service::Client c(client_options(srv->address(), ""));
        const auto list = c.list();
        bool running = false;
        for (const auto& j : list.jobs()) running |= j.state() == v1::RUNNING && j.progress().steps() > 0;
        hits += running;
      }
      const bool hard = round % 3 != 2;
      const int st = srv->stop(hard ? SIGKILL : SIGTERM);
      (hard ? kills : terms) += 1;
      if (!hard) {
        EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "a stopped server must exit cleanly, status " << st;
      }
      srv = std::make_unique<ServerProcess>(state, args);
      ASSERT_TRUE(srv->running()) << srv->errors();
      service::Client c(client_options(srv->address(), ""));
      submit_all(c);  // clients retry with their request ids
    }
    service::Client c(client_options(srv->address(), ""));
    for (const auto& k : cases) {
      ASSERT_TRUE(ids.count(k.name)) << k.name << " was never accepted";
      const auto fin = c.watch(ids[k.name]);
      EXPECT_EQ(fin.state(), v1::SUCCEEDED) << k.name << ": " << fin.error();
    }
    const auto list = c.list();
    EXPECT_EQ(list.jobs_size(), int(cases.size())) << "jobs lost or duplicated";
  }
  // Uninterrupted references with `runout run`, compared file by file.
  int identical = 0, attempts = 0;
  for (const auto& k : cases) {
    const fs::path out = d.p / ("ref-" + k.name);
    const std::string cmd = runout_binary() + " run " + scenario_file(k.s, d.p, k.name).string() + " --out " + out.string() +
                            " --quiet --threads 1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::string hash;
    {
      const auto r = jobs::load_scenario(scenario_file(k.s, d.p, k.name).string());
      hash = jobs::scenario_hash(r);
    }
    const auto a = fingerprint(out), b = fingerprint(state / "results" / hash);
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a.size(), b.size()) << k.name;
    for (const auto& [key, v] : a) EXPECT_EQ(v, b.count(key) ? b.at(key) : "(missing)") << k.name << ": " << key;
    identical += a == b;
  }
  {
    ServerProcess srv(state, args);
    service::Client c(client_options(srv.address(), ""));
    for (const auto& [name, id] : ids) attempts += c.get(id).attempts();
  }
  std::printf("reliability: kills survived %d (kill -9 %d, SIGTERM %d; %d of them while a job ran past its first step), jobs %zu "
              "(attempts %d, submissions retried %d), lost 0, duplicated 0, identical after continuation %d of %zu\n",
              kills + terms, kills, terms, hits, cases.size(), attempts, retries, identical, cases.size());
  EXPECT_EQ(identical, int(cases.size()));
  EXPECT_GE(hits, 3) << "the kills must hit running jobs, or the test proves nothing about continuation";
  EXPECT_GT(attempts, int(cases.size())) << "some job must have run again after a kill";
}

// One writer per state directory: a second server on it exits at once naming the first (pid and
// address); a server on a port another one holds exits too (no port sharing).
TEST(Reliability, SecondServerOnOneStateDirectoryOrPortExits) {
  TempDir d;
  ServerProcess a(d.p / "one" / "state", {});
  ASSERT_TRUE(a.running()) << a.errors();
  ServerOptions refuse;
  refuse.expect_listening = false;
  ServerProcess b(d.p / "one" / "state", {}, refuse);
  EXPECT_FALSE(b.running());
  EXPECT_TRUE(WIFEXITED(b.status()) && WEXITSTATUS(b.status()) == 4) << b.status();
  const std::string e = read_text(d.p / "one" / "server.err");
  EXPECT_NE(e.find("in use by another runout server (pid " + std::to_string(a.pid()) + ", listening on " + a.address()), std::string::npos)
      << e;
  ServerOptions same_port = refuse;
  same_port.listen = a.address();
  ServerProcess c(d.p / "two" / "state", {}, same_port);
  EXPECT_FALSE(c.running());
  EXPECT_NE(read_text(d.p / "two" / "server.err").find("cannot listen on " + a.address()), std::string::npos);
  service::Client client(client_options(a.address(), ""));
  EXPECT_TRUE(client.healthy());
  std::printf("reliability: two servers on one state directory: second refused; two on one port: second refused\n");
}

// A missing, empty or damaged jobs.db beside earlier results refuses to start and says how to
// recover; `runout serve --recover` rebuilds the jobs from their records, logs and results.
TEST(Reliability, DamagedStoreRefusesToStartAndRecovers) {
  TempDir d;
  const fs::path state = d.p / "state";
  std::string done, cancelled;
  {
    ServerProcess srv(state, {"--data-root", kScenarios});
    service::Client c(client_options(srv.address(), ""));
    done = c.submit(arelen(15, 60), "kept").id();
    ASSERT_EQ(c.watch(done).state(), v1::SUCCEEDED);
    const auto blocker = c.submit(arelen(15, 9e4, 0)).id();
    cancelled = c.submit(arelen(15, 9e4 + 1, 0)).id();
    c.cancel(cancelled);
    c.cancel(blocker);
  }
  ServerOptions refuse;
  refuse.expect_listening = false;
  const fs::path db = state / "jobs.db";
  struct Damage {
    const char* what;
    std::function<void()> apply;
    const char* says;
  };
  const std::string saved = read_text(db);
  const std::vector<Damage> damages = {
      {"deleted", [&] { fs::remove(db); }, "is missing"},
      {"empty", [&] { std::ofstream(db, std::ios::trunc).flush(); }, "is empty"},
      {"garbage header", [&] { std::ofstream(db, std::ios::trunc) << std::string(4096, 'x'); }, "jobs.db"},
  };
  for (const auto& dmg : damages) {
    dmg.apply();
    fs::remove(state.string() + "/jobs.db-wal");
    fs::remove(state.string() + "/jobs.db-shm");
    ServerProcess srv(state, {"--data-root", kScenarios}, refuse);
    EXPECT_FALSE(srv.running()) << dmg.what;
    const std::string e = srv.errors();
    EXPECT_NE(e.find(dmg.says), std::string::npos) << dmg.what << ": " << e;
    EXPECT_NE(e.find("--recover"), std::string::npos) << e;
    fs::remove(state.parent_path() / "server.err");
  }
  // Recovery from the last damage (garbage): the jobs come back with their ids, states and owners.
  ServerProcess srv(state, {"--recover", "--data-root", kScenarios});
  ASSERT_TRUE(srv.running()) << srv.errors();
  EXPECT_NE(srv.errors().find("recovered the job store: 3 job(s) rebuilt"), std::string::npos) << srv.errors();
  service::Client c(client_options(srv.address(), ""));
  EXPECT_EQ(c.get(done).state(), v1::SUCCEEDED);
  EXPECT_EQ(c.get(cancelled).state(), v1::CANCELLED);
  EXPECT_EQ(c.submit(arelen(15, 60), "kept").id(), done);  // its request id too
  c.download(done, "max_depth.tif", (d.p / "fetched.tif").string());
  EXPECT_TRUE(fs::exists(d.p / "fetched.tif"));
  bool kept = false;
  for (const auto& e : fs::directory_iterator(state)) kept |= e.path().filename().string().rfind("jobs.db.damaged-", 0) == 0;
  EXPECT_TRUE(kept) << "the damaged store is kept beside the new one";
  (void)saved;
  std::printf("reliability: damaged store (deleted, empty, garbage): refused 3 of 3, recovered 3 of 3 jobs\n");
}

// Tokens fail closed: a tokens file emptied, malformed or deleted accepts no token (and the log says
// why) until it is fixed.
TEST(Reliability, TokensFailClosed) {
  TempDir d;
  const fs::path tokens = d.p / "tokens";
  std::ofstream(tokens) << "alpha\n";
  ServerProcess srv(d.p / "state", {"--tokens", tokens.string()});
  service::Client alpha(client_options(srv.address(), "alpha"));
  auto status = [&] { return code_of([&] { alpha.list(); }); };
  ASSERT_EQ(status(), 0);
  const int refused = int(grpc::StatusCode::UNAUTHENTICATED);
  struct Change {
    const char* what;
    std::function<void()> apply;
  };
  const std::vector<Change> changes = {
      {"emptied", [&] { std::ofstream(tokens, std::ios::trunc) << "# revoked\n"; }},
      {"a malformed line", [&] { std::ofstream(tokens, std::ios::trunc) << "alpha\nsha256:abc\n"; }},
      {"deleted", [&] { fs::remove(tokens); }},
  };
  for (const auto& ch : changes) {
    std::ofstream(tokens, std::ios::trunc) << "alpha\n";
    std::this_thread::sleep_for(20ms);
    EXPECT_EQ(status(), 0) << "before: " << ch.what;
    ch.apply();
    EXPECT_EQ(status(), refused) << "tokens file " << ch.what << ": the old token must not stay valid";
  }
  std::ofstream(tokens, std::ios::trunc) << "alpha\n";
  EXPECT_EQ(status(), 0);
  const std::string log = srv.log();
  EXPECT_NE(log.find("holds no token; no token is accepted"), std::string::npos) << log;
  EXPECT_NE(log.find("needs 64 hex digits; no token is accepted"), std::string::npos) << log;
  EXPECT_NE(log.find("cannot read it; no token is accepted"), std::string::npos) << log;
  std::printf("reliability: tokens file emptied / malformed / deleted: every token refused 3 of 3\n");
}

// A full disk: the server's state directory on a small filesystem the test mounts (tmpfs, 32 MiB),
// filled up. The job that cannot write fails saying the disk is full; an upload and a submission
// (the store's write) are refused saying so; the server stays up, succeeds once space is freed and
// stops cleanly.
TEST(Reliability, FullDiskFailsTheJobNotTheServer) {
  TempDir d;
  const fs::path disk = d.p / "disk";
  fs::create_directories(disk);
  if (std::system(("mount -t tmpfs -o size=32m runout-full-disk-test " + disk.string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "cannot mount a small filesystem here (mounting needs root): the full-disk test did not run";
  struct Unmount {
    fs::path p;
    ~Unmount() { (void)std::system(("umount -l " + p.string()).c_str()); }
  } unmount{disk};
  auto free_bytes = [&] {
    struct statvfs v {};
    statvfs(disk.c_str(), &v);
    return std::int64_t(v.f_bavail) * std::int64_t(v.f_frsize);
  };
  // Fill the disk up to `left` bytes free (a filler file beside the state directory).
  const fs::path filler = disk / "filler";
  auto leave_free = [&](std::int64_t left) {
    fs::remove(filler);
    const std::int64_t n = std::max<std::int64_t>(0, free_bytes() - left);
    std::ofstream f(filler, std::ios::binary);
    const std::string block(1 << 16, 'f');
    for (std::int64_t w = 0; w < n; w += std::int64_t(block.size())) f.write(block.data(), std::streamsize(std::min<std::int64_t>(n - w, std::int64_t(block.size()))));
  };
  ServerProcess srv(disk / "state", {"--data-root", kScenarios});
  ASSERT_TRUE(srv.running()) << srv.errors();
  service::Client c(client_options(srv.address(), ""));
  auto big = arelen(15, 600);
  big.mutable_outputs()->set_timeseries_interval_s(2);
  const std::string failing = [&] {
    std::string id;
    leave_free(12 << 20);
    EXPECT_EQ(code_of([&] { id = c.submit(big).id(); }), 0);
    leave_free(1 << 20);  // the job's frames fill the rest
    return id;
  }();
  const auto fail = c.watch(failing);
  EXPECT_EQ(fail.state(), v1::FAILED);
  EXPECT_NE(fail.error().find("disk is full"), std::string::npos) << fail.error();
  EXPECT_EQ(fail.error().find((disk / "state").string()), std::string::npos) << "names the server's folder: " << fail.error();
  // An upload and a submission (the store's write) on the full disk.
  leave_free(0);
  write_random_file(d.p / "dem.tif", 4 << 20, 5);
  std::string m;
  EXPECT_EQ(code_of([&] { c.upload({(d.p / "dem.tif").string()}); }, &m), int(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_NE(m.find("disk is full"), std::string::npos) << m;
  const int submit_code = code_of([&] { c.submit(arelen(15.25, 60)); }, &m);
  EXPECT_EQ(submit_code, int(grpc::StatusCode::RESOURCE_EXHAUSTED)) << m;
  EXPECT_NE(m.find("disk is full"), std::string::npos) << m;
  EXPECT_TRUE(c.healthy());
  // Space freed: the next job succeeds, and the server stops cleanly.
  fs::remove(filler);
  const auto ok = c.watch(c.submit(arelen(15, 60)).id());
  EXPECT_EQ(ok.state(), v1::SUCCEEDED) << ok.error();
  const int st = srv.stop(SIGTERM);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "status " << st << " (signal " << (WIFSIGNALED(st) ? WTERMSIG(st) : 0) << ")";
  std::printf("reliability: full disk (tmpfs 32 MiB): job failed (%s); upload refused (%s); submission refused (%s, %s); "
              "after freeing space the next job succeeded, the server stopped cleanly\n",
              fail.error().c_str(), code_name(int(grpc::StatusCode::RESOURCE_EXHAUSTED)).c_str(), code_name(submit_code).c_str(), m.c_str());
}

// A file-size limit on the server and its workers (EFBIG, where a test cannot mount a small
// filesystem for a real ENOSPC, this one still runs): the job that cannot write fails with a
// message, the server stays up, the next job succeeds and SIGTERM stops the server cleanly.
TEST(Reliability, FileSizeLimitFailsTheJobNotTheServer) {
  TempDir d;
  ServerOptions o;
  o.file_size_limit = 2 << 20;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios}, o);
  ASSERT_TRUE(srv.running()) << srv.errors();
  service::Client c(client_options(srv.address(), ""));
  auto big = arelen(15, 600);
  big.mutable_outputs()->set_timeseries_interval_s(1);
  const auto fail = c.watch(c.submit(big).id());
  EXPECT_EQ(fail.state(), v1::FAILED);
  EXPECT_FALSE(fail.error().empty());
  EXPECT_EQ(fail.error().find((d.p / "state").string()), std::string::npos) << "names the server's folder: " << fail.error();
  const auto ok = c.watch(c.submit(arelen(15, 60)).id());
  EXPECT_EQ(ok.state(), v1::SUCCEEDED) << ok.error();
  const int st = srv.stop(SIGTERM);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "status " << st << " (signal " << (WIFSIGNALED(st) ? WTERMSIG(st) : 0) << ")";
  std::printf("reliability: file-size limit: the writing job failed (%s), the next succeeded, the server stopped cleanly\n",
              fail.error().c_str());
}

// A job whose own worker process crashes (a signal nobody sent) runs again and fails after three
// crashes, naming the signal; the other jobs and the server are not touched.
TEST(Reliability, CrashingWorkerFailsOnlyItsOwnJob) {
  TempDir d;
  const fs::path state = d.p / "state";
  ServerProcess srv(state, {"--data-root", kScenarios, "--workers", "1"});
  service::Client c(client_options(srv.address(), ""));
  const std::string bad = c.submit(arelen(15, 9e4, 0)).id();
  const std::string good = c.submit(arelen(15.5, 60)).id();
  for (int crash = 1; crash <= 3; ++crash) {
    pid_t pid = -1;
    ASSERT_TRUE(wait_for(
        [&] {
          const auto j = c.get(bad);
          pid = worker_pid(state, bad);
          return j.state() == v1::RUNNING && j.attempts() == crash && pid > 0 &&
                 read_text(state / "logs" / (bad + ".log")).find("attempt " + std::to_string(crash) + ": started") != std::string::npos;
        },
        30s))
        << "crash " << crash;
    std::this_thread::sleep_for(300ms);
    ASSERT_EQ(kill(worker_pid(state, bad), SIGSEGV), 0);
    if (crash == 1) {
      // Meanwhile the good job is not held back for ever: it runs after the bad one is re-queued.
    }
    ASSERT_TRUE(wait_for([&] { return c.get(bad).attempts() > crash || jobs::is_final(c.get(bad).state()); }, 30s));
  }
  const auto fin = c.watch(bad);
  EXPECT_EQ(fin.state(), v1::FAILED);
  EXPECT_NE(fin.error().find("crashed (SIGSEGV) in 3 attempts"), std::string::npos) << fin.error();
  EXPECT_EQ(c.watch(good).state(), v1::SUCCEEDED);
  EXPECT_TRUE(c.healthy());
  std::printf("reliability: worker crashes 3, failed jobs 1 (the crashing one), other jobs succeeded 1 of 1\n");
}

// Limits end a runaway job with a clear reason: wall time (the scenario's limit below the
// server's) and memory.
TEST(Reliability, LimitsEndRunawayJobs) {
  TempDir d;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--workers", "2", "--threads-per-run", "1"});
  service::Client c(client_options(srv.address(), ""));
  auto slow = arelen(15, 9e4, 0);
  slow.mutable_limits()->set_max_wall_s(2);
  auto fat = arelen(15, 9e4 + 1, 0);
  fat.mutable_limits()->set_max_memory_bytes(20 << 20);
  const auto t0 = std::chrono::steady_clock::now();
  const std::string a = c.submit(slow).id(), b = c.submit(fat).id();
  const auto fa = c.watch(a), fb = c.watch(b);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(fa.state(), v1::FAILED);
  EXPECT_NE(fa.error().find("wall-time limit of 2 s"), std::string::npos) << fa.error();
  EXPECT_EQ(fb.state(), v1::FAILED);
  EXPECT_NE(fb.error().find("memory limit"), std::string::npos) << fb.error();
  EXPECT_LT(wall, 30);
  // A limit above the server's is refused at the door.
  auto greedy = arelen();
  greedy.mutable_limits()->set_max_wall_s(1e9);
  std::string m;
  EXPECT_EQ(code_of([&] { c.submit(greedy); }, &m), int(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_NE(m.find("limits.max_wall_s"), std::string::npos) << m;
  std::printf("reliability: limits: wall-time and memory runaways failed with their reasons in %.1f s\n", wall);
}

// Cancel and stop reach a big VOF job (steps of up to 1.5 s) within about a second: they are a
// signal to its process, SIGKILL after stop_grace_s (1 s). operations.md's bounds: a cancel within
// 2 s, a stop of the whole server within 3 s.
TEST(Reliability, CancelAndStopTakeEffectWithinAboutASecond) {
  TempDir d;
  const fs::path state = d.p / "state";
  auto big = coarse_collapse();
  big.mutable_lab()->set_nx(500);
  big.mutable_lab()->set_ny(150);
  big.mutable_lab()->set_end_time_s(5);
  auto srv = std::make_unique<ServerProcess>(state, std::vector<std::string>{"--data-root", kScenarios});
  service::Client c(client_options(srv->address(), ""));
  const std::string id = c.submit(big).id();
  ASSERT_TRUE(wait_for([&] { return c.get(id).state() == v1::RUNNING && worker_pid(state, id) > 0; }, 60s));
  ASSERT_TRUE(wait_for([&] { return c.get(id).progress().steps() > 2; }, 60s));
  EXPECT_EQ(c.get(id).progress().end_time_s(), 5) << "the progress names the lab's end time";
  auto t0 = std::chrono::steady_clock::now();
  c.cancel(id);
  ASSERT_TRUE(wait_for([&] { return c.get(id).state() == v1::CANCELLED; }, 10s));
  const double cancel_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(cancel_s, 2.0);
  auto big2 = big;
  big2.mutable_lab()->set_end_time_s(5.01);
  const std::string id2 = c.submit(big2).id();
  ASSERT_TRUE(wait_for([&] { return c.get(id2).state() == v1::RUNNING && worker_pid(state, id2) > 0; }, 60s));
  std::this_thread::sleep_for(1500ms);
  t0 = std::chrono::steady_clock::now();
  const int st = srv->stop(SIGTERM);
  const double stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << st;
  EXPECT_LT(stop_s, 3.0);  // the server's own shutdown (gRPC) included
  srv = std::make_unique<ServerProcess>(state, std::vector<std::string>{"--data-root", kScenarios});
  service::Client c2(client_options(srv->address(), ""));
  EXPECT_EQ(c2.get(id2).state() == v1::QUEUED || c2.get(id2).state() == v1::RUNNING, true);
  c2.cancel(id2);
  std::printf("reliability: a %d-cell VOF job: cancelled in %.2f s, server stopped in %.2f s\n", 500 * 150, cancel_s, stop_s);
}

// An upgrade that replaces the server's program file while it runs (as a package manager does)
// does not stop it from starting workers: they are the running program, not the file's new content.
TEST(Reliability, ReplacedProgramFileStillRunsJobs) {
  TempDir d;
  const fs::path bin = d.p / "runout";
  fs::copy_file(runout_binary(), bin);
  fs::permissions(bin, fs::perms::owner_all);
  ServerOptions o;
  o.binary = bin.string();
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios}, o);
  ASSERT_TRUE(srv.running()) << srv.errors();
  fs::remove(bin);  // the upgrade: the old file is gone (a new one would take its name)
  std::ofstream(bin) << "#!/bin/sh\nexit 1\n";
  service::Client c(client_options(srv.address(), ""));
  const auto fin = c.watch(c.submit(arelen(15, 60)).id());
  EXPECT_EQ(fin.state(), v1::SUCCEEDED) << fin.error();
  std::printf("reliability: program file replaced while serving: jobs still checked and run by the running program\n");
}

// Three kills of the server while the same job runs (the OOM killer, an operator, a power cut):
// the job still succeeds, since the server's death never counts against it.
TEST(Reliability, ThreeKillsDuringOneJobNeverFailIt) {
  TempDir d;
  const fs::path state = d.p / "state";
  const std::vector<std::string> args = {"--data-root", kScenarios, "--threads-per-run", "1"};
  std::string id;
  for (int kill = 0; kill <= 3; ++kill) {
    ServerProcess srv(state, args);
    ASSERT_TRUE(srv.running()) << srv.errors();
    service::Client c(client_options(srv.address(), ""));
    if (id.empty()) id = c.submit(arelen(15, 600), "three-kills").id();
    if (kill == 3) {
      const auto fin = c.watch(id);
      EXPECT_EQ(fin.state(), v1::SUCCEEDED) << fin.error();
      EXPECT_GE(fin.attempts(), 4);
      std::printf("reliability: 3 kills -9 during one job: %s after %d attempts\n", jobs::state_name(fin.state()).c_str(),
                  fin.attempts());
      break;
    }
    ASSERT_TRUE(wait_for([&] { return c.get(id).state() == v1::RUNNING && c.get(id).progress().steps() > 0; }, 30s))
        << "kill " << kill;
    srv.stop(SIGKILL);
  }
}

// A worker process that does not end after SIGKILL holds no slot for ever: after
// stuck_after_kill_s its job ends and the slot runs the next job. The stuck worker here keeps its
// output open through a process it started (as a process in uninterruptible I/O keeps it: neither
// ends nor closes); the scheduler is the server's, driven directly with that worker program.
TEST(Reliability, AWorkerThatCannotEndReleasesItsSlot) {
  TempDir d;
  const fs::path state = d.p / "state";
  for (const char* sub : {"logs", "results", "checkpoints", "uploads"}) fs::create_directories(state / sub);
  const fs::path exe = d.p / "worker.sh", pids = d.p / "held.pid";
  {
    std::ofstream w(exe);
    w << "#!/bin/sh\ncat > \"$0.task.$$\"\n"
      << "if grep -q stuck-worker \"$0.task.$$\"; then\n  trap '' TERM\n  sleep 600 &\n  echo $! >> " << pids.string()
      << "\n  exec sleep 600\nfi\nexec " << runout_binary() << " worker < \"$0.task.$$\"\n";
  }
  fs::permissions(exe, fs::perms::owner_all);
  jobs::JobStore store((state / "jobs.db").string());
  jobs::SchedulerConfig sc;
  sc.state_dir = state.string();
  sc.workers = 1;
  sc.threads_per_run = 1;
  sc.worker_exe = exe.string();
  sc.stop_grace_s = 0.2;
  sc.stuck_after_kill_s = 1;
  jobs::Scheduler sched(store, sc);
  sched.start();
  auto submit = [&](v1::Scenario s) {
    const fs::path f = scenario_file(s, d.p, s.name());
    const auto r = jobs::load_scenario(f.string());
    const auto out = store.submit("me", jobs::scenario_hash(r), "", r.scenario, 10);
    sched.notify();
    return out.job.job.id();
  };
  auto state_of = [&](const std::string& id) { return store.get(id, "me")->job.state(); };
  auto stuck = arelen(15, 9e4, 0);
  stuck.set_name("stuck-worker");
  const std::string a = submit(stuck);
  ASSERT_TRUE(wait_for([&] { return state_of(a) == v1::RUNNING && fs::exists(pids); }, 30s));
  auto next = arelen(15, 60);
  next.set_name("next");
  const std::string b = submit(next);
  const auto t0 = std::chrono::steady_clock::now();
  store.cancel(a, "me");
  sched.cancel_running(a);
  EXPECT_TRUE(wait_for([&] { return state_of(a) == v1::CANCELLED; }, 10s)) << "the stuck worker's job never ended";
  const double released = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(wait_for([&] { return jobs::is_final(state_of(b)); }, 60s)) << "the next job never ran";
  EXPECT_EQ(state_of(b), v1::SUCCEEDED) << store.get(b, "me")->job.error();
  EXPECT_NE(read_text(state / "logs" / (a + ".log")).find("did not end within 1 s of SIGKILL"), std::string::npos);
  sched.stop();
  std::ifstream in(pids);
  for (pid_t p; in >> p;) kill(p, SIGKILL);
  std::printf("reliability: a worker that cannot end: its job cancelled and its slot released %.2f s after the cancel "
              "(grace 0.2 s, left behind after 1 s); the next job %s\n",
              released, jobs::state_name(state_of(b)).c_str());
}
