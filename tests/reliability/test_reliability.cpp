// The fault-injection suite (ctest label `reliability`): what the job system promises under faults,
// tried as an operator would. Each test starts its own `runout serve` on loopback with a state
// directory of its own and stops it by its pid. Every test prints a `reliability:` line with its
// figures (kills, jobs, lost, duplicated, identical, bad inputs and their codes, fuzz cases, crashes).
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "jobs/scenario.hpp"
#include "jobs/sha256.hpp"
#include "jobs/store.hpp"
#include "terrain/terrain.hpp"
#include "tests/support/server_process.hpp"

namespace fs = std::filesystem;
using namespace runout;
using namespace std::chrono_literals;
using test_support::client_options;
using test_support::read_text;
using test_support::ServerOptions;
using test_support::ServerProcess;
using test_support::TempDir;

namespace {

const std::string kSource = RUNOUT_SOURCE_DIR;
const std::string kScenarios = kSource + "/scenarios";

// In den Arelen at 30 m with its inputs named relative to the scenarios folder (a data root).
v1::Scenario arelen(double bed_friction = 15, double end_time = 600, double stop_fraction = 0.01) {
  auto s = jobs::parse_scenario_json(read_text(kSource + "/tests/data/arelen-30m.json"));
  s.mutable_dem()->set_path("data/arelen/davos_srtm3.tif");
  s.mutable_area_of_interest()->set_path("data/arelen/aoi.geojson");
  s.mutable_releases(0)->set_path("data/arelen/release.geojson");
  s.mutable_material()->set_bed_friction_deg(bed_friction);
  s.mutable_numerics()->set_end_time_s(end_time);
  s.mutable_numerics()->set_stop_fraction(stop_fraction);
  return s;
}

// B2's collapse at 5 mm to 1 s: a VOF job of a few seconds.
v1::Scenario coarse_collapse() {
  auto lab = jobs::load_scenario(kScenarios + "/lab/b2-collapse-0deg.json").scenario;
  lab.mutable_lab()->set_nx(100);
  lab.mutable_lab()->set_ny(30);
  lab.mutable_lab()->set_end_time_s(1.0);
  return lab;
}

// The scenario as a file for `runout run`, its inputs by absolute path.
fs::path scenario_file(const v1::Scenario& s0, const fs::path& dir, const std::string& name) {
  v1::Scenario s = s0;
  auto abs = [](std::string* p) {
    if (!p->empty() && fs::path(*p).is_relative()) *p = kScenarios + "/" + *p;
  };
  abs(s.mutable_dem()->mutable_path());
  if (s.has_area_of_interest()) abs(s.mutable_area_of_interest()->mutable_path());
  for (auto& r : *s.mutable_releases()) abs(r.mutable_path());
  std::string json;
  google::protobuf::util::JsonPrintOptions po;
  po.preserve_proto_field_names = true;
  (void)google::protobuf::util::MessageToJsonString(s, &json, po);
  const fs::path f = dir / (name + ".json");
  std::ofstream(f) << json;
  return f;
}

// Every data set of an HDF5 file, by path: its bytes' SHA-256 (the files as wholes carry times).
std::map<std::string, std::string> h5_datasets(const fs::path& file) {
  std::map<std::string, std::string> out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  struct Ctx {
    hid_t f;
    std::map<std::string, std::string>* out;
  } ctx{f, &out};
  H5Ovisit(
      f, H5_INDEX_NAME, H5_ITER_NATIVE,
      [](hid_t, const char* name, const H5O_info_t* info, void* p) -> herr_t {
        auto* c = static_cast<Ctx*>(p);
        if (info->type != H5O_TYPE_DATASET) return 0;
        const hid_t d = H5Dopen2(c->f, name, H5P_DEFAULT);
        const hid_t t = H5Dget_type(d);
        const hsize_t bytes = H5Dget_storage_size(d);
        std::string buf(std::size_t(std::max<hsize_t>(bytes, 1)) * 4, '\0');
        const hid_t sp = H5Dget_space(d);
        const auto n = H5Sget_simple_extent_npoints(sp);
        buf.resize(std::size_t(n) * H5Tget_size(t));
        if (n > 0) H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data());
        (*c->out)[name] = jobs::sha256_hex(buf);
        H5Sclose(sp);
        H5Tclose(t);
        H5Dclose(d);
        return 0;
      },
      &ctx);
  H5Fclose(f);
  return out;
}

// run.json's figures by path ("solver.steps"), without what differs between equal runs: times,
// the scenario's paths, the continuation.
void flatten(const google::protobuf::Value& v, const std::string& path, std::map<std::string, std::string>& out) {
  if (v.has_struct_value()) {
    for (const auto& [k, x] : v.struct_value().fields()) flatten(x, path.empty() ? k : path + "." + k, out);
    return;
  }
  std::string j;
  (void)google::protobuf::util::MessageToJsonString(v, &j);
  out[path] = j;
}

std::map<std::string, std::string> figures(const fs::path& run_json) {
  google::protobuf::Value v;
  std::map<std::string, std::string> out;
  if (!google::protobuf::util::JsonStringToMessage(read_text(run_json), &v).ok()) return {{"unreadable", run_json.string()}};
  auto& f = *v.mutable_struct_value()->mutable_fields();
  for (const char* k : {"timings_s", "created_utc", "scenario_file", "scenario", "inputs"}) f.erase(k);
  if (f.count("solver")) f["solver"].mutable_struct_value()->mutable_fields()->erase("continued_from_t_s");
  flatten(v, "", out);
  return out;
}

// What "identical" means: the same bytes in every raster and outline, in every HDF5 data set,
// and the same run.json figures.
std::map<std::string, std::string> fingerprint(const fs::path& dir) {
  std::map<std::string, std::string> fp;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string(), ext = e.path().extension().string();
    if (ext == ".tif" || n == "outline.geojson") fp[n] = terrain::sha256_file(e.path().string());
    if (ext == ".h5")
      for (const auto& [k, v] : h5_datasets(e.path())) fp[n + ":" + k] = v;
    if (n == "run.json")
      for (const auto& [k, v] : figures(e.path())) fp[n + ":" + k] = v;
  }
  return fp;
}

int code_of(const std::function<void()>& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const service::RpcError& e) {
    if (message) *message = e.what();
    return e.code;
  }
  return 0;
}

std::string code_name(int c) {
  static const char* names[] = {"OK", "CANCELLED", "UNKNOWN", "INVALID_ARGUMENT", "DEADLINE_EXCEEDED", "NOT_FOUND", "ALREADY_EXISTS",
                                "PERMISSION_DENIED", "RESOURCE_EXHAUSTED", "FAILED_PRECONDITION", "ABORTED", "OUT_OF_RANGE",
                                "UNIMPLEMENTED", "INTERNAL", "UNAVAILABLE", "DATA_LOSS", "UNAUTHENTICATED"};
  return c >= 0 && c <= 16 ? names[c] : std::to_string(c);
}

bool wait_for(const std::function<bool()>& cond, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (cond()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return cond();
}

// The pid of the job's current worker process, from its log ("worker process PID").
pid_t worker_pid(const fs::path& state, const std::string& id) {
  const std::string log = read_text(state / "logs" / (id + ".log"));
  const auto k = log.rfind("worker process ");
  if (k == std::string::npos) return -1;
  return pid_t(std::atol(log.c_str() + k + 15));
}

}  // namespace

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
  int kills = 0, terms = 0, retries = 0;
  auto submit_all = [&](service::Client& c) {
    for (const auto& k : cases) {
      std::string id;
      if (code_of([&] { id = c.submit(k.s, "rel-" + k.name).id(); }) != 0) {
        ++retries;
        continue;
      }
      if (ids.count(k.name)) EXPECT_EQ(ids[k.name], id) << "a retry of " << k.name << " got another job";
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
      const bool hard = round % 3 != 2;
      const int st = srv->stop(hard ? SIGKILL : SIGTERM);
      (hard ? kills : terms) += 1;
      if (!hard) EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "a stopped server must exit cleanly, status " << st;
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
    const std::string cmd = std::string(RUNOUT_BIN) + " run " + scenario_file(k.s, d.p, k.name).string() + " --out " + out.string() +
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
  std::printf("reliability: kills survived %d (kill -9 %d, SIGTERM %d), jobs %zu (attempts %d, submissions retried %d), lost 0, "
              "duplicated 0, identical after continuation %d of %zu\n",
              kills + terms, kills, terms, cases.size(), attempts, retries, identical, cases.size());
  EXPECT_EQ(identical, int(cases.size()));
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

// A full disk (a file-size limit on the server and its workers): the job that cannot write fails
// with a message, the server stays up, the next job succeeds and SIGTERM stops the server cleanly.
TEST(Reliability, FullDiskFailsTheJobNotTheServer) {
  TempDir d;
  ServerOptions o;
  o.file_size_limit = 2 << 20;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios}, o);
  ASSERT_TRUE(srv.running()) << srv.errors();
  service::Client c(client_options(srv.address(), ""));
  auto big = arelen(15, 600);
  big.mutable_outputs()->set_timeseries_interval_s(0.5);
  const auto fail = c.watch(c.submit(big).id());
  EXPECT_EQ(fail.state(), v1::FAILED);
  EXPECT_FALSE(fail.error().empty());
  EXPECT_EQ(fail.error().find((d.p / "state").string()), std::string::npos) << "names the server's folder: " << fail.error();
  const auto ok = c.watch(c.submit(arelen(15, 60)).id());
  EXPECT_EQ(ok.state(), v1::SUCCEEDED) << ok.error();
  const int st = srv.stop(SIGTERM);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "status " << st << " (signal " << (WIFSIGNALED(st) ? WTERMSIG(st) : 0) << ")";
  std::printf("reliability: full disk: the writing job failed (%s), the next succeeded, the server stopped cleanly\n",
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

// Cancel and stop reach a big VOF job within about a second: they are a signal to its process.
TEST(Reliability, CancelAndStopTakeEffectWithinASecond) {
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
  EXPECT_LT(cancel_s, 2.5);
  auto big2 = big;
  big2.mutable_lab()->set_end_time_s(5.01);
  const std::string id2 = c.submit(big2).id();
  ASSERT_TRUE(wait_for([&] { return c.get(id2).state() == v1::RUNNING && worker_pid(state, id2) > 0; }, 60s));
  std::this_thread::sleep_for(1500ms);
  t0 = std::chrono::steady_clock::now();
  const int st = srv->stop(SIGTERM);
  const double stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << st;
  EXPECT_LT(stop_s, 8);  // the server's own shutdown (gRPC) included
  srv = std::make_unique<ServerProcess>(state, std::vector<std::string>{"--data-root", kScenarios});
  service::Client c2(client_options(srv->address(), ""));
  EXPECT_EQ(c2.get(id2).state() == v1::QUEUED || c2.get(id2).state() == v1::RUNNING, true);
  c2.cancel(id2);
  std::printf("reliability: a %d-cell VOF job: cancelled in %.2f s, server stopped in %.2f s\n", 500 * 150, cancel_s, stop_s);
}

// Concurrent clients, each sending every submission twice at once with one request id: one job per
// (client, request id), no job lost.
TEST(Reliability, ConcurrentClientsWithDuplicatedRequestIds) {
  TempDir d;
  const fs::path tokens = d.p / "tokens";
  {
    std::ofstream t(tokens);
    for (int k = 0; k < 8; ++k) t << "token-" << k << "\n";
  }
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--tokens", tokens.string(), "--workers", "2"});
  std::mutex mu;
  std::map<std::string, std::set<std::string>> answers;  // client/request -> job ids
  std::atomic<int> failures{0}, submissions{0};
  std::vector<std::thread> clients;
  for (int k = 0; k < 8; ++k)
    clients.emplace_back([&, k] {
      for (int s = 0; s < 3; ++s) {
        const auto sc = arelen(14 + s, 60);
        const std::string rid = "req-" + std::to_string(s);
        std::vector<std::thread> twins;
        for (int twin = 0; twin < 2; ++twin)
          twins.emplace_back([&, twin] {
            (void)twin;
            service::Client c(client_options(srv.address(), "token-" + std::to_string(k)));
            ++submissions;
            try {
              const auto j = c.submit(sc, rid);
              std::lock_guard lk(mu);
              answers[std::to_string(k) + "/" + rid].insert(j.id());
            } catch (const std::exception&) {
              ++failures;
            }
          });
        for (auto& t : twins) t.join();
      }
    });
  for (auto& t : clients) t.join();
  int duplicated = 0, jobs = 0;
  for (const auto& [key, set] : answers) duplicated += int(set.size()) - 1;
  for (int k = 0; k < 8; ++k) {
    service::Client c(client_options(srv.address(), "token-" + std::to_string(k)));
    const auto list = c.list();
    jobs += list.jobs_size();
    for (const auto& j : list.jobs()) EXPECT_TRUE(jobs::is_final(c.watch(j.id()).state()));
  }
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(answers.size(), 24u);
  EXPECT_EQ(duplicated, 0);
  EXPECT_EQ(jobs, 24);
  std::printf("reliability: 8 clients, %d submissions (each request id twice at once): jobs %d of 24 expected, lost %d, duplicated %d\n",
              submissions.load(), jobs, 24 - jobs, duplicated);
}

namespace {

struct BadCase {
  std::string name;
  std::function<void(v1::Scenario&)> mutate;
  int code;
  std::string says;  // what the message must name
};

std::vector<BadCase> bad_cases() {
  const int bad = int(grpc::StatusCode::INVALID_ARGUMENT);
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {"grid.crs unknown", [](v1::Scenario& s) { s.mutable_grid()->set_crs("EPSG:999999"); }, bad, "grid.crs"},
      {"grid.crs geographic", [](v1::Scenario& s) { s.mutable_grid()->set_crs("EPSG:4326"); }, bad, "grid.crs"},
      {"grid.resolution_m too fine", [](v1::Scenario& s) { s.mutable_grid()->set_resolution_m(0.001); }, bad, "grid.resolution_m"},
      {"grid.resolution_m too coarse", [](v1::Scenario& s) { s.mutable_grid()->set_resolution_m(1e9); }, bad, "grid.resolution_m"},
      {"release slope window empty",
       [](v1::Scenario& s) {
         s.mutable_releases(0)->set_min_slope_deg(89.9);
         s.mutable_releases(0)->set_max_slope_deg(89.95);
       },
       bad, "release.geojson"},
      {"thickness attribute missing", [](v1::Scenario& s) { s.mutable_releases(0)->set_thickness_attribute("depth"); }, bad,
       "no attribute 'depth'"},
      {"release is the DEM", [](v1::Scenario& s) { s.mutable_releases(0)->set_path("data/arelen/davos_srtm3.tif"); }, bad,
       "davos_srtm3.tif"},
      {"DEM is a vector file", [](v1::Scenario& s) { s.mutable_dem()->set_path("data/arelen/release.geojson"); }, bad, "release.geojson"},
      {"thickness 1e300", [](v1::Scenario& s) { s.mutable_releases(0)->set_thickness_m(1e300); }, bad, "thickness"},
      {"density infinite", [inf](v1::Scenario& s) { s.mutable_material()->set_density_kg_m3(inf); }, bad, "density_kg_m3"},
      {"cfl 1e-12", [](v1::Scenario& s) { s.mutable_numerics()->set_cfl(1e-12); }, bad, "numerics.cfl"},
      {"end time infinite", [inf](v1::Scenario& s) { s.mutable_numerics()->set_end_time_s(inf); }, bad, "numerics.end_time_s"},
      {"dem path with ..", [](v1::Scenario& s) { s.mutable_dem()->set_path("../x.tif"); }, bad, "dem.path"},
      {"dem path outside the roots", [](v1::Scenario& s) { s.mutable_dem()->set_path("/etc/passwd"); }, bad, "dem.path"},
      {"limits above the server's", [](v1::Scenario& s) { s.mutable_limits()->set_max_wall_s(1e12); }, bad, "limits.max_wall_s"},
      {"negative memory limit", [](v1::Scenario& s) { s.mutable_limits()->set_max_memory_bytes(-1); }, bad, "limits.max_memory_bytes"},
      {"vof without lab", [](v1::Scenario& s) { s.set_engine("vof"); }, bad, "lab"},
      {"vof fill outside",
       [](v1::Scenario& s) {
         s = coarse_collapse();
         for (auto& f : *s.mutable_lab()->mutable_fill()) {
           f.set_x_min(50);
           f.set_x_max(51);
         }
       },
       bad, "lab.fill"},
      {"vof end time infinite",
       [inf](v1::Scenario& s) {
         s = coarse_collapse();
         s.mutable_lab()->set_end_time_s(inf);
       },
       bad, "lab.end_time_s"},
  };
}

}  // namespace

// Every check `runout run` makes happens at the door: each bad scenario is refused by
// SubmitScenario with its code and a message naming the field or the user's file (never the
// server's upload folder); refused uploads are removed.
TEST(Reliability, BadScenariosAreRefusedAtTheDoor) {
  TempDir d;
  const fs::path state = d.p / "state";
  ServerProcess srv(state, {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  std::map<std::string, int> codes;
  int refused = 0;
  for (const auto& bc : bad_cases()) {
    auto s = arelen();
    bc.mutate(s);
    std::string m;
    const int code = code_of([&] { c.submit(s); }, &m);
    codes[code_name(code)]++;
    refused += code == bc.code;
    EXPECT_EQ(code, bc.code) << bc.name << ": " << m;
    EXPECT_NE(m.find(bc.says), std::string::npos) << bc.name << ": " << m;
    EXPECT_EQ(m.find(state.string()), std::string::npos) << bc.name << " names the server's folder: " << m;
    std::printf("bad input: %-30s -> %s: %s\n", bc.name.c_str(), code_name(code).c_str(), m.c_str());
  }
  // Uploaded inputs of a refused submission are removed; messages name the user's file.
  auto s = arelen();
  s.mutable_releases(0)->set_thickness_attribute("depth");
  const auto up = service::upload_inputs(c, s, kScenarios);
  std::string m;
  EXPECT_EQ(code_of([&] { c.submit(up); }, &m), int(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_NE(m.find("'release.geojson'"), std::string::npos) << m;
  EXPECT_EQ(m.find("uploads"), std::string::npos) << m;
  int left = 0;
  for (const auto& e : fs::directory_iterator(state / "uploads")) left += e.path().filename().string()[0] != '.';
  EXPECT_EQ(left, 0) << "uploads of a refused submission are removed";
  std::string summary;
  for (const auto& [k, v] : codes) summary += " " + k + " " + std::to_string(v);
  std::printf("reliability: bad inputs tried %zu, refused with the expected code %d; codes:%s\n", bad_cases().size(), refused,
              summary.c_str());
}

// A bounded fuzz run: mutated scenarios through SubmitScenario; the server never crashes or hangs,
// and never answers INTERNAL.
TEST(Reliability, FuzzedScenariosNeitherCrashNorHangTheServer) {
  TempDir d;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--workers", "1"});
  std::mt19937 rng(77);
  const double specials[] = {0, -1, 1e-300, 1e300, -1e300, 1e-9, 1e9, 2147483648.0, 90, 89.999,
                             std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()};
  const int n = 40;
  int accepted = 0, internal = 0, crashes = 0, hangs = 0;
  std::map<std::string, int> codes;
  for (int k = 0; k < n; ++k) {
    v1::Scenario s = k % 5 == 4 ? coarse_collapse() : arelen();
    const auto* desc = s.GetDescriptor();
    (void)desc;
    // 1-3 mutations of numeric fields anywhere in the message, by reflection.
    const int m = 1 + int(rng() % 3);
    for (int j = 0; j < m; ++j) {
      std::vector<std::pair<google::protobuf::Message*, const google::protobuf::FieldDescriptor*>> fields;
      std::function<void(google::protobuf::Message*)> collect = [&](google::protobuf::Message* msg) {
        const auto* r = msg->GetReflection();
        const auto* dsc = msg->GetDescriptor();
        for (int f = 0; f < dsc->field_count(); ++f) {
          const auto* fd = dsc->field(f);
          if (fd->is_repeated()) {
            if (fd->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE)
              for (int i = 0; i < r->FieldSize(*msg, fd); ++i) collect(r->MutableRepeatedMessage(msg, fd, i));
            continue;
          }
          if (fd->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE) {
            if (r->HasField(*msg, fd)) collect(r->MutableMessage(msg, fd));
          } else {
            fields.push_back({msg, fd});
          }
        }
      };
      collect(&s);
      if (fields.empty()) break;
      auto [msg, fd] = fields[rng() % fields.size()];
      const auto* r = msg->GetReflection();
      const double v = specials[rng() % (sizeof specials / sizeof specials[0])];
      switch (fd->cpp_type()) {
        case google::protobuf::FieldDescriptor::CPPTYPE_DOUBLE: r->SetDouble(msg, fd, v); break;
        case google::protobuf::FieldDescriptor::CPPTYPE_FLOAT: r->SetFloat(msg, fd, float(v)); break;
        case google::protobuf::FieldDescriptor::CPPTYPE_INT32: r->SetInt32(msg, fd, std::isfinite(v) ? int(std::clamp(v, -2e9, 2e9)) : -7); break;
        case google::protobuf::FieldDescriptor::CPPTYPE_INT64: r->SetInt64(msg, fd, std::isfinite(v) ? std::int64_t(std::clamp(v, -9e18, 9e18)) : -7); break;
        case google::protobuf::FieldDescriptor::CPPTYPE_BOOL: r->SetBool(msg, fd, !r->GetBool(*msg, fd)); break;
        case google::protobuf::FieldDescriptor::CPPTYPE_STRING: {
          const char* strs[] = {"", "?", "../../etc/passwd", "EPSG:0", "%s%n", "dém"};
          r->SetString(msg, fd, strs[rng() % 6]);
          break;
        }
        default: break;
      }
    }
    service::ClientOptions o = client_options(srv.address(), "");
    o.timeout_s = 90;
    service::Client c(o);
    std::string msg;
    std::string id;
    const int code = code_of([&] { id = c.submit(s).id(); }, &msg);
    codes[code_name(code)]++;
    if (code == 0) {
      ++accepted;
      c.cancel(id);
    }
    internal += code == int(grpc::StatusCode::INTERNAL);
    hangs += code == int(grpc::StatusCode::DEADLINE_EXCEEDED);
    EXPECT_NE(code, int(grpc::StatusCode::INTERNAL)) << "case " << k << ": " << msg;
    if (!srv.running() || kill(srv.pid(), 0) != 0 || !c.healthy()) {
      ++crashes;
      ADD_FAILURE() << "the server died on fuzz case " << k;
      break;
    }
  }
  std::string summary;
  for (const auto& [k, v] : codes) summary += " " + k + " " + std::to_string(v);
  std::printf("reliability: fuzz cases %d, accepted %d, crashes %d, hangs %d, internal errors %d; codes:%s\n", n, accepted, crashes,
              hangs, internal, summary.c_str());
  EXPECT_EQ(crashes, 0);
  EXPECT_EQ(hangs, 0);
}

// Uploads are bounded: a client's uploads beyond its quota are refused, and uploads that no queued
// or running job uses are removed after the upload time-to-live.
TEST(Reliability, UploadsHaveAQuotaAndAreCollected) {
  TempDir d;
  const fs::path cfg = d.p / "server.json";
  std::ofstream(cfg) << R"({"upload_ttl_s": 1, "max_upload_bytes_per_client": 20000})";
  const fs::path state = d.p / "state";
  ServerProcess srv(state, {"--config", cfg.string()});
  ASSERT_TRUE(srv.running()) << srv.errors();
  service::Client c(client_options(srv.address(), ""));
  const std::string dem = kScenarios + "/data/arelen/davos_srtm3.tif";  // 14 kB
  const auto up = c.upload({dem});
  EXPECT_EQ(up.ref().rfind("upload:", 0), 0u);
  std::string m;
  EXPECT_EQ(code_of([&] { c.upload({kScenarios + "/data/arelen/release.geojson", dem}); }, &m),
            int(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_NE(m.find("quota"), std::string::npos) << m;
  auto count = [&] {
    int n = 0;
    for (const auto& e : fs::directory_iterator(state / "uploads")) n += e.path().filename().string()[0] != '.';
    return n;
  };
  EXPECT_EQ(count(), 1);
  EXPECT_TRUE(wait_for([&] { return count() == 0; }, 10s)) << "an unused upload outlived its time-to-live";
  EXPECT_EQ(code_of([&] { c.upload({dem}); }), 0) << "the quota is free again";
  std::printf("reliability: uploads: over-quota upload refused, unused uploads collected after their time-to-live\n");
}

// An upgrade that replaces the server's program file while it runs (as a package manager does)
// does not stop it from starting workers: they are the running program, not the file's new content.
TEST(Reliability, ReplacedProgramFileStillRunsJobs) {
  TempDir d;
  const fs::path bin = d.p / "runout";
  fs::copy_file(RUNOUT_BIN, bin);
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
