// The batch service end to end: the real `runout serve` process on 127.0.0.1 with an ephemeral port
// and a temporary state directory, driven through the client library.
#include <gdal_priv.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <thread>

#include "jobs/formats/run_record.hpp"
#include "jobs/scenario/scenario.hpp"
#include "jobs/digest/sha256.hpp"
#include "jobs/system/store.hpp"
#include <sqlite3.h>
#include "service/client/client.hpp"
#include "tests/support/server_process.hpp"

namespace fs = std::filesystem;
using namespace runout;
using namespace std::chrono_literals;
using runout::test_support::client_options;
using runout::test_support::read_text;
using runout::test_support::ServerProcess;
using runout::test_support::TempDir;

namespace {

// The In den Arelen test scenario (30 m) with its inputs named relative to the scenarios folder.
v1::Scenario arelen(double end_time = 600, double stop_fraction = 0.01) {
  auto s = jobs::parse_scenario_json(read_text(std::string(RUNOUT_SOURCE_DIR) + "/tests/data/arelen-30m.json"));
  s.mutable_dem()->set_path("data/arelen/davos_srtm3.tif");
  s.mutable_area_of_interest()->set_path("data/arelen/aoi.geojson");
  s.mutable_releases(0)->set_path("data/arelen/release.geojson");
  s.mutable_numerics()->set_end_time_s(end_time);
  s.mutable_numerics()->set_stop_fraction(stop_fraction);
  return s;
}

void write_tokens(const fs::path& p) {
  std::ofstream t(p);
  t << "# test tokens\nalpha-token\nsha256:" << jobs::sha256_hex("beta-token") << "\n";
}

std::vector<float> raster(const fs::path& p) {
  GDALAllRegister();
  GDALDatasetUniquePtr d(GDALDataset::Open(p.c_str(), GDAL_OF_RASTER));
  if (!d) return {};
  std::vector<float> v(std::size_t(d->GetRasterXSize()) * d->GetRasterYSize());
  if (d->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, d->GetRasterXSize(), d->GetRasterYSize(), v.data(), d->GetRasterXSize(),
                                    d->GetRasterYSize(), GDT_Float32, 0, 0) != CE_None)
    return {};
  return v;
}

int code_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const service::RpcError& e) {
    return e.code;
  }
  return 0;
}

const std::string kScenarios = std::string(RUNOUT_SOURCE_DIR) + "/scenarios";

}  // namespace

TEST(Service, SubmitWatchFetchWithUploadsAndServerPaths) {
  TempDir d;
  write_tokens(d.p / "tokens");
  ServerProcess srv(d.p / "state", {"--tokens", (d.p / "tokens").string(), "--data-root", kScenarios, "--workers", "2"});
  ASSERT_FALSE(srv.address().empty());
  service::Client c(client_options(srv.address(), "alpha-token"));
  EXPECT_TRUE(c.healthy());
  // Inputs uploaded from the client side.
  auto s = service::upload_inputs(c, arelen(), kScenarios);
  EXPECT_EQ(s.dem().path().rfind("upload:", 0), 0u);
  const auto j = c.submit(s);
  std::vector<v1::JobState> seen;
  int with_progress = 0;
  const auto fin = c.watch(j.id(), [&](const v1::Job& ev) {
    if (seen.empty() || seen.back() != ev.state()) seen.push_back(ev.state());
    if (ev.state() == v1::RUNNING && ev.progress().steps() > 0) ++with_progress;
  });
  EXPECT_EQ(fin.state(), v1::SUCCEEDED) << fin.error();
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), v1::SUCCEEDED);
  EXPECT_GE(with_progress, 1);
  ASSERT_GE(fin.transitions_size(), 3);  // submitted, started, completed
  EXPECT_GT(fin.result_bytes(), 0);
  const auto files = c.results(j.id());
  std::set<std::string> names;
  for (const auto& f : files.files()) names.insert(f.name());
  for (const char* n : {"max_depth.tif", "max_speed.tif", "outline.geojson", "map_max_depth.png", "run.json", "job.log"})
    EXPECT_TRUE(names.count(n)) << n;
  c.download(j.id(), "max_depth.tif", (d.p / "max_depth.tif").string());
  const auto v = raster(d.p / "max_depth.tif");
  ASSERT_FALSE(v.empty());
  EXPECT_GT(*std::max_element(v.begin(), v.end()), 1.0f);
  // The same scenario named by server paths has the same hash: the same job answers.
  const auto again = c.submit(arelen());
  EXPECT_EQ(again.id(), j.id());
  EXPECT_EQ(again.scenario_hash(), j.scenario_hash());
  // A result name outside the list is refused (no path tricks).
  EXPECT_EQ(code_of([&] { c.download(j.id(), "../jobs.db", (d.p / "x").string()); }), int(grpc::StatusCode::NOT_FOUND));
}

// A scenario with a structure and a 3D nest through the service: the structure's and the nest's
// files are uploaded with the others, and the nest's own results (its run.json, the loads) are
// listed one folder down and fetched by that name.
TEST(Service, ANestedScenarioWithAStructureRunsAndItsNestsResultsAreFetched) {
  TempDir d;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--workers", "1", "--threads-per-run", "1"});
  ASSERT_FALSE(srv.address().empty());
  service::Client c(client_options(srv.address(), ""));
  auto sc = arelen();  // 30 m cells; the nest's columns too (about 10 s on one thread)
  auto* st = sc.add_structures();
  st->set_name("farmhouse");
  st->set_path("data/arelen/farmhouse.geojson");
  st->set_height_m(8);
  sc.mutable_nest()->set_path("data/arelen/farmhouse-nest.geojson");
  sc.mutable_nest()->set_refinement(1);
  const auto up = service::upload_inputs(c, sc, kScenarios);
  EXPECT_EQ(up.structures(0).path().rfind("upload:", 0), 0u);
  EXPECT_EQ(up.nest().path().rfind("upload:", 0), 0u);
  const auto fin = c.watch(c.submit(up).id());
  ASSERT_EQ(fin.state(), v1::SUCCEEDED) << fin.error();
  std::set<std::string> names;
  const auto listing = c.results(fin.id());
  for (const auto& f : listing.files()) names.insert(f.name());
  for (const char* n : {"run.json", "max_pressure.tif", "nest/run.json", "nest/structure_loads.csv", "nest/structure_loads.png", "nest/max_depth.tif"})
    EXPECT_TRUE(names.count(n)) << n;
  fs::create_directories(d.p / "got/nest");
  c.download(fin.id(), "run.json", (d.p / "got/run.json").string());
  c.download(fin.id(), "nest/run.json", (d.p / "got/nest/run.json").string());
  const auto rec = jobs::read_run_record((d.p / "got/run.json").string()), inner = jobs::read_run_record((d.p / "got/nest/run.json").string());
  ASSERT_EQ(rec.nest().structures_size(), 1);
  EXPECT_GT(rec.nest().structures(0).peak_force_kn(), 0);
  EXPECT_FALSE(rec.nest().structures(0).loads_resolved());  // 30 m columns
  EXPECT_LT(rec.nest().inflow_relative_difference(), 0.01);
  ASSERT_EQ(inner.structures_size(), 1);
  EXPECT_EQ(inner.structures(0).peak_force_kn(), rec.nest().structures(0).peak_force_kn());
  // What the clients accept as a result's name: a file, or one folder and a file.
  EXPECT_TRUE(service::result_name_ok("nest/run.json"));
  EXPECT_TRUE(service::result_name_ok("run.json"));
  for (const char* bad : {"", ".hidden", "../jobs.db", "nest/../x", "a/b/c", "nest/", "/abs", "a\\b", "nest/.x"})
    EXPECT_FALSE(service::result_name_ok(bad)) << bad;
  // Only listed names download: a path into the folder's parent is refused.
  EXPECT_EQ(code_of([&] { c.download(fin.id(), "nest/../run.json", (d.p / "x").string()); }), int(grpc::StatusCode::NOT_FOUND));
}

TEST(Service, IdempotentResubmissionAndRequestIds) {
  TempDir d;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  // Held in the queue behind a long job, so that nothing finishes during the checks.
  const auto blocker = c.submit(arelen(9e4, 0));
  const auto a = c.submit(arelen(500));
  const auto b = c.submit(arelen(500));
  EXPECT_EQ(a.id(), b.id());
  const auto r1 = c.submit(arelen(400), "client-key-1");
  // A retry (the same request id and scenario) is answered by the first job ...
  const auto r2 = c.submit(arelen(400), "client-key-1");
  EXPECT_EQ(r1.id(), r2.id());
  // ... and the request id reused for another scenario is refused, naming the first job.
  try {
    c.submit(arelen(450), "client-key-1");
    ADD_FAILURE() << "a request id reused with another scenario was accepted";
  } catch (const service::RpcError& e) {
    EXPECT_EQ(e.code, int(grpc::StatusCode::ALREADY_EXISTS)) << e.what();
    EXPECT_NE(std::string(e.what()).find(r1.id()), std::string::npos) << e.what();
  }
  EXPECT_NE(r1.id(), a.id());
  const auto list = c.list();
  EXPECT_EQ(list.jobs_size(), 3);
  // Paging: one job per page, every job once.
  std::set<std::string> ids;
  std::string token;
  do {
    const auto page = c.list({}, 1, token);
    for (const auto& j : page.jobs()) ids.insert(j.id());
    token = page.next_page_token();
  } while (!token.empty());
  EXPECT_EQ(ids.size(), 3u);
  EXPECT_EQ(c.list({v1::RUNNING}).jobs_size() + c.list({v1::QUEUED}).jobs_size(), 3);
  // Even after it was cancelled, the request id names that job.
  c.cancel(r1.id());
  EXPECT_EQ(c.submit(arelen(400), "client-key-1").id(), r1.id());
  // Cancelled jobs end so; a new identical submission is a new job.
  EXPECT_EQ(c.cancel(a.id()).state(), v1::CANCELLED);
  EXPECT_NE(c.submit(arelen(500)).id(), a.id());
  c.cancel(blocker.id());
}

TEST(Service, CancelWhileRunning) {
  TempDir d;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  const auto j = c.submit(arelen(9e4, 0));  // runs until cancelled
  for (int k = 0; k < 200; ++k) {
    const auto g = c.get(j.id());
    if (g.state() == v1::RUNNING && g.progress().steps() > 0) break;
    std::this_thread::sleep_for(50ms);
  }
  const auto r = c.cancel(j.id());
  EXPECT_EQ(r.state(), v1::RUNNING);  // asked; the run stops at its next progress point
  const auto fin = c.watch(j.id());
  EXPECT_EQ(fin.state(), v1::CANCELLED);
  const auto files = c.results(j.id());
  ASSERT_EQ(files.files_size(), 1);  // the log only
  EXPECT_EQ(files.files(0).name(), "job.log");
  EXPECT_EQ(code_of([&] { c.download(j.id(), "max_depth.tif", (d.p / "x").string()); }),
            int(grpc::StatusCode::FAILED_PRECONDITION));
  // Nothing half-written is left under results/.
  for (const auto& e : fs::directory_iterator(d.p / "state/results")) ADD_FAILURE() << e.path();
}

TEST(Service, BadScenariosTokensAndPathsGetTheRightCodes) {
  TempDir d;
  write_tokens(d.p / "tokens");
  fs::create_directories(d.p / "root");
  fs::create_symlink("/etc/hostname", d.p / "root/escape.tif");
  ServerProcess srv(d.p / "state", {"--tokens", (d.p / "tokens").string(), "--data-root", kScenarios, "--data-root",
                                    (d.p / "root").string(), "--log-file", (d.p / "log").string()});
  service::Client alpha(client_options(srv.address(), "alpha-token"));
  service::Client beta(client_options(srv.address(), "beta-token"));  // listed by its SHA-256
  service::Client none(client_options(srv.address(), ""));
  service::Client wrong(client_options(srv.address(), "gamma-token"));
  EXPECT_EQ(code_of([&] { none.list(); }), int(grpc::StatusCode::UNAUTHENTICATED));
  EXPECT_EQ(code_of([&] { wrong.submit(arelen()); }), int(grpc::StatusCode::UNAUTHENTICATED));
  EXPECT_TRUE(none.healthy());  // health checking needs no token
  // Bad scenarios: INVALID_ARGUMENT naming the field.
  auto s = arelen();
  s.mutable_material()->set_bed_friction_deg(95);
  try {
    alpha.submit(s);
    FAIL();
  } catch (const service::RpcError& e) {
    EXPECT_EQ(e.code, int(grpc::StatusCode::INVALID_ARGUMENT));
    EXPECT_NE(std::string(e.what()).find("material.bed_friction_deg"), std::string::npos) << e.what();
  }
  s = arelen();
  s.mutable_numerics()->set_limiter("vanLeer");
  EXPECT_EQ(code_of([&] { alpha.submit(s); }), int(grpc::StatusCode::INVALID_ARGUMENT));
  // More MPI ranks than the server gives a job (max_ranks_per_job; locally the machine's cores).
  s = arelen();
  s.set_engine("vof");
  s.set_ranks(100000);
  try {
    alpha.submit(s);
    FAIL();
  } catch (const service::RpcError& e) {
    EXPECT_EQ(e.code, int(grpc::StatusCode::INVALID_ARGUMENT));
    EXPECT_NE(std::string(e.what()).find("ranks: must lie in 1.."), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("max_ranks_per_job"), std::string::npos) << e.what();
  }
  // Paths outside the data roots: '..', absolute paths elsewhere, links that leave a root; every
  // input field is held to them, a release's thickness raster too.
  const std::pair<const char*, std::function<void(v1::Scenario&, const std::string&)>> fields[] = {
      {"dem.path", [](v1::Scenario& sc, const std::string& p) { sc.mutable_dem()->set_path(p); }},
      {"releases[0].thickness_raster", [](v1::Scenario& sc, const std::string& p) { sc.mutable_releases(0)->set_thickness_raster(p); }}};
  for (const auto& [field, set] : fields)
    for (const std::string p : {"../tests/data/arelen-30m.json", "/etc/hostname", "escape.tif", "data/arelen/missing.tif"}) {
      s = arelen();
      set(s, p);
      try {
        alpha.submit(s);
        ADD_FAILURE() << p << " was accepted as " << field;
      } catch (const service::RpcError& e) {
        EXPECT_EQ(e.code, int(grpc::StatusCode::INVALID_ARGUMENT)) << field << ": " << p;
        EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
      }
    }
  s = arelen();
  s.mutable_dem()->set_path("upload:" + std::string(64, 'a') + "/dem.tif");
  try {
    alpha.submit(s);
    ADD_FAILURE() << "a missing upload was accepted";
  } catch (const service::RpcError& e) {
    EXPECT_EQ(e.code, int(grpc::StatusCode::NOT_FOUND));
    EXPECT_NE(std::string(e.what()).find("upload the file again"), std::string::npos) << e.what();
  }
  // Formats that can point at other files (a VRT naming a file outside the roots) are refused.
  {
    std::ofstream v(d.p / "dem.vrt");
    v << "<VRTDataset rasterXSize=\"10\" rasterYSize=\"10\"><VRTRasterBand dataType=\"Float32\" band=\"1\"><SimpleSource>"
         "<SourceFilename relativeToVRT=\"0\">/etc/hostname</SourceFilename></SimpleSource></VRTRasterBand></VRTDataset>\n";
  }
  s = arelen();
  s.mutable_dem()->set_path(alpha.upload({(d.p / "dem.vrt").string()}).ref());
  EXPECT_EQ(code_of([&] { alpha.submit(s); }), int(grpc::StatusCode::INVALID_ARGUMENT));
  // A token sees only its own jobs.
  const auto j = alpha.submit(arelen(300));
  EXPECT_EQ(code_of([&] { beta.get(j.id()); }), int(grpc::StatusCode::NOT_FOUND));
  EXPECT_EQ(code_of([&] { beta.cancel(j.id()); }), int(grpc::StatusCode::NOT_FOUND));
  EXPECT_EQ(beta.list().jobs_size(), 0);
  EXPECT_EQ(code_of([&] { alpha.get("jdoesnotexist"); }), int(grpc::StatusCode::NOT_FOUND));
  alpha.watch(j.id());
}

// The server's settings for jobs over MPI ranks are checked at its start, naming the key.
TEST(Service, BadRanksSettingsStopTheServerAtItsStart) {
  TempDir d;
  for (const auto& [json, key] : std::vector<std::pair<std::string, std::string>>{
           {R"({"max_ranks_per_job": -2})", "max_ranks_per_job: must lie in 1..65536"},
           {R"({"mpi_launcher": [""]})", "mpi_launcher: its first word"},
           {R"({"slurm_mpi": "pmix; rm -rf /"})", "slurm_mpi: 'pmix; rm -rf /' is not an MPI plugin's name"}}) {
    std::ofstream(d.p / "server.json") << json;
    const std::string cmd = std::string(RUNOUT_BIN) + " serve --config " + (d.p / "server.json").string() + " --state-dir " +
                            (d.p / "state").string() + " --listen 127.0.0.1:0 2> " + (d.p / "err").string();
    EXPECT_NE(std::system(cmd.c_str()), 0) << json;
    std::ifstream in(d.p / "err");
    const std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(err.find(key), std::string::npos) << json << ": " << err;
  }
}

// A job over MPI ranks whose launcher is missing fails at once, naming the launcher (not as a
// crash run again three times).
TEST(Service, AJobOverRanksWithoutItsLauncherFailsAndSaysWhy) {
  TempDir d;
  std::ofstream(d.p / "server.json") << R"({"mpi_launcher": ["/nonexistent/mpirun"], "max_ranks_per_job": 4})";
  ServerProcess srv(d.p / "state", {"--config", (d.p / "server.json").string(), "--data-root", kScenarios, "--threads-per-run", "1"});
  service::Client c(client_options(srv.address(), ""));
  auto s = jobs::parse_scenario_json(read_text(kScenarios + "/in-den-arelen-3d-regress.json"));  // paths inside the data root
  s.mutable_numerics()->set_end_time_s(1);
  s.set_ranks(2);
  const auto fin = c.watch(c.submit(s).id());
  EXPECT_EQ(fin.state(), v1::FAILED);
  EXPECT_NE(fin.error().find("the launcher '/nonexistent/mpirun' was not found"), std::string::npos) << fin.error();
  EXPECT_EQ(fin.attempts(), 1);
}

TEST(Service, QueueLimitPerClient) {
  TempDir d;
  write_tokens(d.p / "tokens");
  std::ofstream(d.p / "server.json") << R"({"max_queued_per_client": 2, "data_roots": [")" << kScenarios << R"("], "tokens_file": ")"
                                      << (d.p / "tokens").string() << R"("})";
  ServerProcess srv(d.p / "state", {"--config", (d.p / "server.json").string()});
  service::Client c(client_options(srv.address(), "alpha-token"));
  service::Client other(client_options(srv.address(), "beta-token"));
  const auto a = c.submit(arelen(9e4, 0));
  const auto b = c.submit(arelen(9e4 + 1, 0));
  EXPECT_EQ(code_of([&] { c.submit(arelen(9e4 + 2, 0)); }), int(grpc::StatusCode::RESOURCE_EXHAUSTED));
  // The limit is per client: another token still gets in.
  const auto o = other.submit(arelen(9e4 + 3, 0));
  other.cancel(o.id());
  c.cancel(a.id());
  c.cancel(b.id());
}

TEST(Service, KilledServerFinishesEveryJobAfterRestart) {
  TempDir d;
  // Run to the end time (no kinetic-energy stop), so that the first job is still running when the
  // server is killed: stopped by the kinetic energy it ends within a second of its first step. It
  // runs while the other two are submitted (each checked in a worker of its own first): to 300 s it
  // took 0.4 s and was often over before the kill; to 6000 s it takes about 6 s on one core.
  const std::vector<double> ends = {6000, 301, 302};
  std::vector<std::string> ids;
  {
    ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--workers", "1"});
    service::Client c(client_options(srv.address(), ""));
    for (double e : ends) ids.push_back(c.submit(arelen(e, 0)).id());
    // Kill -9 while the first job is in the middle of its run.
    for (int k = 0; k < 400; ++k) {
      const auto g = c.get(ids[0]);
      if (g.state() == v1::RUNNING && g.progress().steps() > 0) break;
      std::this_thread::sleep_for(25ms);
    }
    EXPECT_EQ(c.get(ids[0]).state(), v1::RUNNING);
    srv.stop(SIGKILL);
  }
  // Restart on the same state directory: every job finishes.
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--workers", "1"});
  service::Client c(client_options(srv.address(), ""));
  for (const auto& id : ids) {
    const auto fin = c.watch(id);
    EXPECT_EQ(fin.state(), v1::SUCCEEDED) << id << " " << fin.error();
  }
  const auto first = c.get(ids[0]);
  EXPECT_EQ(first.attempts(), 2);
  bool requeued = false;
  for (const auto& t : first.transitions()) requeued |= t.reason().find("queued to run again") != std::string::npos;
  EXPECT_TRUE(requeued);
  // The results equal an uninterrupted run's, value for value.
  TempDir ref;
  ServerProcess other(ref.p / "state", {"--data-root", kScenarios, "--workers", "2"});
  service::Client c2(client_options(other.address(), ""));
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const auto j = c2.watch(c2.submit(arelen(ends[k], 0)).id());
    ASSERT_EQ(j.state(), v1::SUCCEEDED);
    const fs::path fa = d.p / "a.tif", fb = d.p / "b.tif";
    fs::remove(fa);
    fs::remove(fb);
    c.download(ids[k], "max_depth.tif", fa.string());
    c2.download(j.id(), "max_depth.tif", fb.string());
    const auto va = raster(fa), vb = raster(fb);
    ASSERT_FALSE(va.empty());
    EXPECT_EQ(va, vb) << "job " << ids[k];
  }
}

TEST(Service, TerminatedServerRequeuesItsRunningJob) {
  TempDir d;
  std::string id;
  {
    ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
    service::Client c(client_options(srv.address(), ""));
    id = c.submit(arelen(9e4, 0)).id();
    for (int k = 0; k < 200 && c.get(id).state() != v1::RUNNING; ++k) std::this_thread::sleep_for(25ms);
    srv.stop(SIGTERM);
  }
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  const auto j = c.get(id);
  bool interrupted = false;
  for (const auto& t : j.transitions()) interrupted |= t.reason().find("interrupted by the server stopping") != std::string::npos;
  EXPECT_TRUE(interrupted);
  EXPECT_NE(j.state(), v1::FAILED);
  c.cancel(id);
}

namespace {
// B2's collapse at 5 mm to 1 s: a VOF job of a few seconds.
v1::Scenario coarse_collapse() {
  auto lab = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b2-collapse-0deg.json").scenario;
  lab.mutable_lab()->set_nx(100);
  lab.mutable_lab()->set_ny(30);
  lab.mutable_lab()->set_end_time_s(1.0);
  return lab;
}

// Submits `s` to a server on `state`, stops that server (SIGTERM) once the job has simulated more
// than `t_min` seconds; returns the job's id and the simulated time last reported.
std::pair<std::string, double> submit_and_stop_after(const fs::path& state, const v1::Scenario& s, double t_min) {
  ServerProcess srv(state, {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  const std::string id = c.submit(s).id();
  for (int k = 0; k < 6000; ++k) {  // up to a minute: a loaded machine runs the job slowly
    const auto g = c.get(id);
    if (g.state() == v1::RUNNING && g.progress().simulated_s() > t_min) break;
    std::this_thread::sleep_for(10ms);
  }
  const double t = c.get(id).progress().simulated_s();
  srv.stop(SIGTERM);
  return {id, t};
}
}  // namespace

// A VOF job interrupted by the server stopping continues from its checkpoint after the restart,
// and its results are the uninterrupted run's: the same frames and monitor samples in run.json.
TEST(Service, StoppedServerContinuesAVofJobFromItsCheckpoint) {
  const auto lab = coarse_collapse();
  TempDir d;
  const auto [id, t_stop] = submit_and_stop_after(d.p / "state", lab, 0.3);
  ASSERT_GT(t_stop, 0.3);
  EXPECT_TRUE(fs::exists(d.p / "state" / "checkpoints" / (id + ".h5")));
  EXPECT_TRUE(fs::exists(d.p / "state" / "checkpoints" / (id + ".h5.fields.h5")));
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  const auto fin = c.watch(id);
  ASSERT_EQ(fin.state(), v1::SUCCEEDED) << fin.error();
  bool continued = false;
  for (const auto& t : fin.transitions()) continued |= t.reason().find("queued to continue from its checkpoint") != std::string::npos;
  EXPECT_TRUE(continued);
  EXPECT_FALSE(fs::exists(d.p / "state" / "checkpoints" / (id + ".h5")));  // gone with the finished job
  c.download(id, "run.json", (d.p / "continued.json").string());
  // The same scenario uninterrupted, on a second server.
  TempDir ref;
  ServerProcess other(ref.p / "state", {"--data-root", kScenarios});
  service::Client c2(client_options(other.address(), ""));
  const auto whole = c2.watch(c2.submit(lab).id());
  ASSERT_EQ(whole.state(), v1::SUCCEEDED);
  c2.download(whole.id(), "run.json", (d.p / "whole.json").string());
  const auto a = jobs::read_run_record((d.p / "continued.json").string()), b = jobs::read_run_record((d.p / "whole.json").string());
  EXPECT_GT(a.solver().continued_from_t_s(), 0.2);
  EXPECT_EQ(a.results().frames(), b.results().frames());
  EXPECT_EQ(a.monitors().t_s_size(), b.monitors().t_s_size());
  EXPECT_GT(b.monitors().t_s_size(), 40);
  EXPECT_NEAR(a.results().front_x_m(), b.results().front_x_m(), 1e-9);
  EXPECT_NEAR(a.results().volume_final_m3(), b.results().volume_final_m3(), 1e-6 * b.results().volume_final_m3());
}

// A checkpoint the server cannot continue (here: damaged) does not fail the job: it runs again
// from the start and says so in its log; a checkpoint left by a job that will not run again is
// removed when the server starts.
TEST(Service, DamagedCheckpointRunsTheVofJobFromTheStart) {
  TempDir d;
  const std::string id = submit_and_stop_after(d.p / "state", coarse_collapse(), 0.2).first;
  const fs::path cp = d.p / "state" / "checkpoints" / (id + ".h5");
  ASSERT_TRUE(fs::exists(cp));
  std::ofstream(cp, std::ios::trunc) << "damaged";
  std::ofstream(d.p / "state" / "checkpoints" / "no-such-job.h5") << "left over";
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  EXPECT_FALSE(fs::exists(d.p / "state" / "checkpoints" / "no-such-job.h5"));
  const auto fin = c.watch(id);
  ASSERT_EQ(fin.state(), v1::SUCCEEDED) << fin.error();
  c.download(id, "job.log", (d.p / "job.log").string());
  const std::string log = read_text(d.p / "job.log");
  EXPECT_NE(log.find("running again from the start"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(cp));
}

// The server's death never counts against a job (its worker process died with the server, the
// job did not crash): any number of requeues after a killed server leave it queued; only the
// crashes of its own worker, recorded with the attempt, are counted.
TEST(Store, ServerDeathsDoNotCountAgainstAJob) {
  TempDir d;
  jobs::JobStore store((d.p / "jobs.db").string());
  const auto id = store.submit("client", "hash", "", v1::Scenario(), 10).job.job.id();
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(store.claim_next());
    EXPECT_EQ(store.requeue_running("the server went down during the run"), 1) << "death " << k;
  }
  ASSERT_TRUE(store.claim_next());
  store.transition(id, v1::QUEUED, "its worker process crashed (SIGSEGV)", "", -1, true);
  const auto j = store.get(id);
  ASSERT_TRUE(j);
  EXPECT_EQ(j->job.attempts(), 6);
  EXPECT_EQ(j->job.state(), v1::QUEUED);
  EXPECT_EQ(j->crashes, 1);
}

// A store written before the newer columns existed (clean interruptions, crashes) gets them.
TEST(Store, OldStoreGetsTheNewColumns) {
  TempDir d;
  const std::string path = (d.p / "jobs.db").string();
  std::string id;
  {
    jobs::JobStore store(path);
    id = store.submit("client", "hash", "", v1::Scenario(), 10).job.job.id();
    ASSERT_TRUE(store.claim_next());
    store.transition(id, v1::QUEUED, "interrupted by the server stopping at t = 0.5 s; queued to continue from its checkpoint");
  }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "ALTER TABLE jobs DROP COLUMN interrupted; ALTER TABLE jobs DROP COLUMN crashes", nullptr, nullptr, nullptr),
            SQLITE_OK);  // the old schema
  sqlite3_close(db);
  jobs::JobStore store(path);
  ASSERT_TRUE(store.claim_next());
  EXPECT_EQ(store.requeue_running("the server went down during the run"), 1);
  EXPECT_EQ(store.get(id)->job.state(), v1::QUEUED);
  EXPECT_EQ(store.get(id)->crashes, 0);
}

TEST(Service, TlsWithTheServersCertificate) {
  TempDir d;
  const std::string cmd = "openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=localhost -addext "
                          "subjectAltName=IP:127.0.0.1,DNS:localhost -keyout " +
                          (d.p / "key.pem").string() + " -out " + (d.p / "cert.pem").string() + " 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "openssl could not make a test certificate";
  write_tokens(d.p / "tokens");
  ServerProcess srv(d.p / "state", {"--tls-cert", (d.p / "cert.pem").string(), "--tls-key", (d.p / "key.pem").string(),
                                    "--tokens", (d.p / "tokens").string(), "--data-root", kScenarios});
  auto o = client_options(srv.address(), "alpha-token");
  o.tls_ca = (d.p / "cert.pem").string();
  service::Client tls(o);
  EXPECT_TRUE(tls.healthy());
  const auto j = tls.submit(arelen(200));
  EXPECT_EQ(tls.watch(j.id()).state(), v1::SUCCEEDED);
  // A plaintext client does not get through.
  auto p = client_options(srv.address(), "alpha-token");
  p.timeout_s = 5;
  service::Client plain(p);
  EXPECT_EQ(code_of([&] { plain.list(); }), int(grpc::StatusCode::UNAVAILABLE));
}

TEST(Service, UploadLimitAndTokenRotation) {
  TempDir d;
  write_tokens(d.p / "tokens");
  std::ofstream(d.p / "server.json") << R"({"max_upload_bytes": 20000, "tokens_file": ")" << (d.p / "tokens").string() << R"("})";
  ServerProcess srv(d.p / "state", {"--config", (d.p / "server.json").string()});
  service::Client alpha(client_options(srv.address(), "alpha-token"));
  // The 14 kB DEM fits, a 40 kB file does not.
  EXPECT_EQ(alpha.upload({kScenarios + "/data/arelen/davos_srtm3.tif"}).ref().rfind("upload:", 0), 0u);
  {
    std::ofstream big(d.p / "big.tif", std::ios::binary);
    big << std::string(40000, 'x');
  }
  EXPECT_EQ(code_of([&] { alpha.upload({(d.p / "big.tif").string()}); }), int(grpc::StatusCode::RESOURCE_EXHAUSTED));
  // Rotation: a new token works without a restart once it is in the file, an old one stops working.
  service::Client gamma(client_options(srv.address(), "gamma-token"));
  EXPECT_EQ(code_of([&] { gamma.list(); }), int(grpc::StatusCode::UNAUTHENTICATED));
  std::this_thread::sleep_for(20ms);  // a distinct modification time
  {
    std::ofstream t(d.p / "tokens.new");
    t << "gamma-token\n";
  }
  fs::rename(d.p / "tokens.new", d.p / "tokens");
  EXPECT_EQ(code_of([&] { gamma.list(); }), 0);
  EXPECT_EQ(code_of([&] { alpha.list(); }), int(grpc::StatusCode::UNAUTHENTICATED));
}

TEST(Service, RetentionRemovesOldResultsAndSaysSo) {
  TempDir d;
  std::string id;
  {
    ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
    service::Client c(client_options(srv.address(), ""));
    id = c.submit(arelen(200)).id();
    ASSERT_EQ(c.watch(id).state(), v1::SUCCEEDED);
    EXPECT_GT(c.list().result_bytes_total(), 0);
  }
  // Restarted with a disk limit of one byte: the results go at start, the job record stays.
  std::ofstream(d.p / "server.json") << R"({"retention_max_bytes": 1, "data_roots": [")" << kScenarios << R"("]})";
  ServerProcess srv(d.p / "state", {"--config", (d.p / "server.json").string()});
  service::Client c(client_options(srv.address(), ""));
  const auto j = c.get(id);
  EXPECT_EQ(j.state(), v1::SUCCEEDED);
  EXPECT_EQ(j.result_bytes(), 0);
  EXPECT_NE(j.transitions(j.transitions_size() - 1).reason().find("retention"), std::string::npos);
  const auto left = c.results(id);  // the log stays
  ASSERT_EQ(left.files_size(), 1);
  EXPECT_EQ(left.files(0).name(), "job.log");
  EXPECT_EQ(code_of([&] { c.download(id, "max_depth.tif", (d.p / "x.tif").string()); }), int(grpc::StatusCode::FAILED_PRECONDITION));
  EXPECT_EQ(c.list().result_bytes_total(), 0);
  // Submitting the scenario again computes it again.
  const auto again = c.submit(arelen(200));
  EXPECT_NE(again.id(), id);
  EXPECT_EQ(c.watch(again.id()).state(), v1::SUCCEEDED);
}

TEST(Service, EnsembleSurvivesAKilledServerAndEqualsTheLocalAggregate) {
  TempDir d;
  const std::string file = std::string(RUNOUT_SOURCE_DIR) + "/tests/data/arelen-ensemble-30m.json";
  // The same ensemble locally (runout run: the embedded job system), as the reference.
  const std::string cmd = std::string(RUNOUT_BIN) + " run " + file + " --out " + (d.p / "local").string() + " --state-dir " +
                          (d.p / "local-state").string() + " --workers 2 --quiet";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  auto s = jobs::parse_scenario_json(read_text(file));
  s.mutable_dem()->set_path("data/arelen/davos_srtm3.tif");
  s.mutable_area_of_interest()->set_path("data/arelen/aoi.geojson");
  s.mutable_releases(0)->set_path("data/arelen/release.geojson");
  std::string id;
  {
    ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--workers", "1"});
    service::Client c(client_options(srv.address(), ""));
    const auto j = c.submit(s);
    id = j.id();
    EXPECT_EQ(j.members().total(), 4);
    // Kill -9 once a member has finished and the next one runs.
    for (int k = 0; k < 2400 && c.get(id).members().succeeded() < 1; ++k) std::this_thread::sleep_for(25ms);
    const auto mid = c.get(id);
    EXPECT_GE(mid.members().succeeded(), 1);
    EXPECT_LT(mid.members().succeeded(), 4) << "the ensemble finished before the server could be killed";
    srv.stop(SIGKILL);
  }
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios, "--workers", "2"});
  service::Client c(client_options(srv.address(), ""));
  const auto fin = c.watch(id);
  ASSERT_EQ(fin.state(), v1::SUCCEEDED) << fin.error();
  EXPECT_EQ(fin.members().succeeded(), 4);
  // No member lost, none run twice to the end: the aggregate is the local one, byte for byte.
  int compared = 0;
  const auto listing = c.results(id);
  for (const auto& f : listing.files()) {
    const fs::path ext = fs::path(f.name()).extension();
    if (ext != ".tif" && ext != ".csv") continue;
    const fs::path got = d.p / ("service-" + f.name());
    c.download(id, f.name(), got.string());
    EXPECT_EQ(read_text(got), read_text(d.p / "local" / f.name())) << f.name();
    ++compared;
  }
  EXPECT_EQ(compared, 14);
  // An ensemble lists as one job; its members are listed on request, in order, each with its results.
  EXPECT_EQ(c.list().jobs_size(), 1);
  const auto members = c.members(id);
  ASSERT_EQ(members.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(members[std::size_t(k)].member_index(), k);
    EXPECT_EQ(members[std::size_t(k)].parent_id(), id);
    EXPECT_EQ(members[std::size_t(k)].state(), v1::SUCCEEDED);
  }
  const auto member_files = c.results(members[1].id());
  EXPECT_TRUE(std::any_of(member_files.files().begin(), member_files.files().end(),
                          [](const v1::ResultFile& f) { return f.name() == "max_depth.tif"; }));
}
