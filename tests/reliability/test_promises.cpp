// The fault-injection suite (ctest label `reliability`), the service's promises on what clients
// send and what a run reports: refused uploads removed whatever the reason, request ids that always
// name one job, bounded text, bounded frame intervals, concurrent uploads within the quota, the log
// of a cancel, a quick stop after a large fetch, and the notes of a clipped release and of
// near-vertical terrain. Each test prints a `reliability:` line with its figures.
#include <ogrsf_frmts.h>

#include "tests/support/local_raster.hpp"
#include "tests/support/reliability_helpers.hpp"

using namespace runout::test_support::reliability;
using runout::test_support::write_local_raster;

namespace {

int uploads_left(const fs::path& state) {
  int n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(state / "uploads", ec)) n += e.path().filename().string()[0] != '.';
  return n;
}

// `runout ARGS` with its standard error kept; returns the exit status and the wall time.
struct Ran {
  int code = -1;
  double seconds = 0;
  std::string err;
};
Ran run_cli(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "cli.err";
  const auto t0 = std::chrono::steady_clock::now();
  const int st = std::system((runout_binary() + " " + args + " > /dev/null 2> " + err.string()).c_str());
  Ran r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.err = read_text(err);
  return r;
}

std::string run_json_text(const fs::path& out) { return read_text(out / "run.json"); }

}  // namespace

// A submission refused for any reason removes its uploads at once: here a DEM that is not in a
// format the server reads (refused before the inputs resolve).
TEST(Reliability, RefusedUploadsAreRemovedWhateverTheReason) {
  TempDir d;
  const fs::path state = d.p / "state";
  ServerProcess srv(state, {});
  ASSERT_TRUE(srv.running()) << srv.errors();
  service::Client c(client_options(srv.address(), ""));
  int refused = 0;
  for (unsigned k = 0; k < 3; ++k) {
    write_random_file(d.p / "dem.tif", 4 << 20, 11 + k);
    auto s = arelen();
    s.mutable_dem()->set_path(c.upload({(d.p / "dem.tif").string()}).ref());
    s.mutable_area_of_interest()->set_path(c.upload({kScenarios + "/data/arelen/aoi.geojson"}).ref());
    s.mutable_releases(0)->set_path(c.upload({kScenarios + "/data/arelen/release.geojson"}).ref());
    std::string m;
    refused += code_of([&] { c.submit(s); }, &m) == int(grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(m.find("not in a format this server reads"), std::string::npos) << m;
    EXPECT_EQ(uploads_left(state), 0) << "the refused submission's uploads stay (" << m << ")";
  }
  EXPECT_EQ(refused, 3);
  // Refused before its inputs are looked at: for its text, and for a request id that names another job.
  auto upload_dem = [&](unsigned seed) {
    write_random_file(d.p / "dem.tif", 1 << 20, seed);
    auto s = arelen();
    s.mutable_dem()->set_path(c.upload({(d.p / "dem.tif").string()}).ref());
    return s;
  };
  auto text = upload_dem(21);
  text.set_name("two\nlines");
  EXPECT_EQ(code_of([&] { c.submit(text); }), int(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_EQ(uploads_left(state), 0) << "refused for its text";
  auto plain = arelen();
  for (auto* p : {plain.mutable_dem()->mutable_path(), plain.mutable_area_of_interest()->mutable_path(), plain.mutable_releases(0)->mutable_path()})
    *p = c.upload({kScenarios + "/" + *p}).ref();
  const std::string job = c.submit(plain, "R").id();
  const int kept = uploads_left(state);  // the job's three inputs
  EXPECT_EQ(code_of([&] { c.submit(upload_dem(23), "R"); }), int(grpc::StatusCode::ALREADY_EXISTS));
  EXPECT_EQ(uploads_left(state), kept) << "refused for its request id";
  c.cancel(job);
  std::printf("reliability: refused submissions (an unreadable 4 MiB DEM 3 times, a line break in the name, a request id of "
              "another job): their uploads left %d\n", uploads_left(state) - kept);
}

// A request id names one job, also when the answer is an earlier identical job: another scenario
// with it is refused, the retry gets the job, and `runout serve --recover` keeps the rule.
TEST(Reliability, ARequestIdAlwaysNamesOneJob) {
  TempDir d;
  const fs::path state = d.p / "state";
  const std::vector<std::string> args = {"--data-root", kScenarios};
  const auto a = arelen(15, 60), b = arelen(16, 60);
  std::string ja;
  const int exists = int(grpc::StatusCode::ALREADY_EXISTS);
  {
    ServerProcess srv(state, args);
    service::Client c(client_options(srv.address(), ""));
    ja = c.submit(a).id();  // no request id
    EXPECT_EQ(c.watch(ja).state(), v1::SUCCEEDED);
    EXPECT_EQ(c.submit(a, "X").id(), ja) << "the identical scenario answers with its job";
    std::string m;
    EXPECT_EQ(code_of([&] { c.submit(b, "X"); }, &m), exists) << "request id X already names job " << ja;
    EXPECT_NE(m.find(ja), std::string::npos) << m;
    std::string again;
    EXPECT_EQ(code_of([&] { again = c.submit(a, "X").id(); }), 0);
    EXPECT_EQ(again, ja) << "a retry of the first request gets its job";
    EXPECT_EQ(c.list().jobs_size(), 1) << "one job";
  }
  // The store lost: rebuilt from the records and logs, the request id still names the job.
  for (const char* f : {"jobs.db", "jobs.db-wal", "jobs.db-shm"}) fs::remove(state / f);
  ServerProcess srv(state, {"--recover", "--data-root", kScenarios});
  ASSERT_TRUE(srv.running()) << srv.errors();
  service::Client c(client_options(srv.address(), ""));
  EXPECT_EQ(code_of([&] { c.submit(b, "X"); }), exists) << "after --recover";
  std::string again;
  EXPECT_EQ(code_of([&] { again = c.submit(a, "X").id(); }), 0);
  EXPECT_EQ(again, ja);
  EXPECT_EQ(c.list().jobs_size(), 1);
  std::printf("reliability: a request id answered by an earlier identical job: after --recover another scenario %s, the retry %s, "
              "jobs %d\n", code_name(code_of([&] { c.submit(b, "X"); })).c_str(), again == ja ? "got its job" : "got another job",
              c.list().jobs_size());
}

// Text is bounded and checked at the door, naming the field: a 10 MiB name, a 100,000-character
// path, a NUL byte in a path, a control character in a request id. `runout run` and `runout
// submit` refuse them the same way, at once.
TEST(Reliability, TextIsBoundedAndCheckedAtTheDoor) {
  TempDir d;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  struct Case {
    const char* what;
    std::function<void(v1::Scenario&)> mutate;
    const char* field;
  };
  const std::vector<Case> cases = {
      {"10 MiB name", [](v1::Scenario& s) { s.set_name(std::string(10 << 20, 'n')); }, "name: longer than 1000 bytes"},
      {"100,000-character path", [](v1::Scenario& s) { s.mutable_dem()->set_path(std::string(100000, 'p')); }, "dem.path: longer than 4096 bytes"},
      {"NUL byte in a path", [](v1::Scenario& s) { s.mutable_releases(0)->set_path(std::string("data/arelen/release.geojson\0.txt", 32)); },
       "releases[0].path: holds a control character (U+0000)"},
  };
  int named = 0;
  for (const auto& k : cases) {
    auto s = arelen();
    k.mutate(s);
    std::string m;
    const auto t0 = std::chrono::steady_clock::now();
    const int code = code_of([&] { c.submit(s); }, &m);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(code, int(grpc::StatusCode::INVALID_ARGUMENT)) << k.what << ": " << m.substr(0, 300);
    EXPECT_NE(m.find(k.field), std::string::npos) << k.what << ": " << m.substr(0, 300);
    EXPECT_LT(wall, 10) << k.what;
    named += m.find(k.field) != std::string::npos;
    // The same scenario as a file: `runout run` (exit 4, at once, no results) and `runout submit`.
    const fs::path file = scenario_file(s, d.p, "text");
    const auto run = run_cli("run " + file.string() + " --out " + (d.p / "out").string() + " --quiet", d.p);
    EXPECT_EQ(run.code, 4) << k.what << ": " << run.err.substr(0, 300);
    EXPECT_NE(run.err.find(k.field), std::string::npos) << k.what << ": " << run.err.substr(0, 300);
    EXPECT_LT(run.seconds, 10) << k.what;
    EXPECT_FALSE(fs::exists(d.p / "out")) << k.what;
    const auto sub = run_cli("submit " + file.string() + " --server " + srv.address(), d.p);
    EXPECT_EQ(sub.code, 4) << k.what << ": " << sub.err.substr(0, 300);
    EXPECT_NE(sub.err.find(k.field), std::string::npos) << k.what << ": " << sub.err.substr(0, 300);
  }
  std::string m;
  EXPECT_EQ(code_of([&] { c.submit(arelen(), "line\nbreak"); }, &m), int(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_NE(m.find("request_id: holds a control character (U+000A)"), std::string::npos) << m;
  EXPECT_TRUE(c.healthy());
  std::printf("reliability: bounded text: %d of %zu refused at the door naming the field (and by run and submit)\n", named, cases.size());
}

// Frames and checkpoints have a lower bound on their interval: at most 1000 over the run.
TEST(Reliability, FrameIntervalsHaveALowerBound) {
  TempDir d;
  ServerProcess srv(d.p / "state", {"--data-root", kScenarios});
  service::Client c(client_options(srv.address(), ""));
  auto every_step = arelen(15, 600);
  every_step.mutable_outputs()->set_timeseries_interval_s(1e-3);
  std::string m;
  EXPECT_EQ(code_of([&] { c.submit(every_step); }, &m), int(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_NE(m.find("outputs.timeseries_interval_s: at least numerics.end_time_s / 1000 (0.6 s"), std::string::npos) << m;
  auto lab = coarse_collapse();
  lab.mutable_lab()->set_write_interval_s(1e-4);
  EXPECT_EQ(code_of([&] { c.submit(lab); }, &m), int(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_NE(m.find("lab.write_interval_s: at least lab.end_time_s / 1000"), std::string::npos) << m;
  auto long_lab = coarse_collapse();  // frames unset: the default 0.05 s becomes end time / 1000
  long_lab.mutable_lab()->set_end_time_s(100);
  long_lab.mutable_lab()->set_write_interval_s(0);
  EXPECT_EQ(code_of([&] { c.cancel(c.submit(long_lab).id()); }, &m), 0) << m;
  every_step.mutable_outputs()->set_timeseries_interval_s(0.6);  // the bound itself is accepted
  EXPECT_EQ(code_of([&] { c.cancel(c.submit(every_step).id()); }, &m), 0) << m;
  std::printf("reliability: frame intervals below end time / 1000 refused (depth-averaged, laboratory)\n");
}

// Uploads of one client at once cannot together exceed its quota.
TEST(Reliability, ConcurrentUploadsStayWithinTheQuota) {
  TempDir d;
  const fs::path cfg = d.p / "server.json";
  std::ofstream(cfg) << R"({"max_upload_bytes_per_client": 3145728})";  // 3 MiB
  ServerProcess srv(d.p / "state", {"--config", cfg.string()});
  ASSERT_TRUE(srv.running()) << srv.errors();
  const int rounds = 3;
  int over = 0;
  for (int round = 0; round < rounds; ++round) {
    std::vector<std::thread> t;
    std::atomic<int> ok{0};
    std::atomic<int> ready{0};
    std::vector<std::string> refs(2);
    for (int k = 0; k < 2; ++k) {
      const fs::path f = d.p / ("in" + std::to_string(round) + "-" + std::to_string(k) + ".tif");
      write_random_file(f, 2 << 20, unsigned(100 * round + k));
      t.emplace_back([&, f, k] {
        service::Client c(client_options(srv.address(), ""));
        ++ready;
        while (ready.load() < 2) std::this_thread::yield();
        if (code_of([&] { refs[std::size_t(k)] = c.upload({f.string()}).ref(); }) == 0) ++ok;
      });
    }
    for (auto& th : t) th.join();
    over += ok.load() > 1;
    EXPECT_LE(ok.load(), 1) << "two 2 MiB uploads at once under a 3 MiB quota were both accepted";
    // Free the quota for the next round: the accepted upload is removed by a refused submission.
    service::Client c(client_options(srv.address(), ""));
    for (const auto& r : refs) {
      if (r.empty()) continue;
      auto s = arelen();
      s.mutable_dem()->set_path(r);
      (void)code_of([&] { c.submit(s); });
    }
  }
  std::printf("reliability: two 2 MiB uploads at once under a 3 MiB quota: both accepted in %d of %d rounds\n", over, rounds);
}

// A cancelled queued job's log says so before anyone can see it cancelled (a client, or
// `runout serve --recover` after a crash).
TEST(Reliability, ACancelIsLoggedBeforeItIsSeen) {
  TempDir d;
  const fs::path state = d.p / "state";
  ServerProcess srv(state, {"--data-root", kScenarios, "--workers", "1"});
  service::Client c(client_options(srv.address(), ""));
  const std::string blocker = c.submit(arelen(15, 9e4, 0)).id();
  int seen = 0, unlogged = 0;
  for (int k = 0; k < 8; ++k) {
    const std::string id = c.submit(arelen(15, 9e4 + 1 + k, 0)).id();
    std::atomic<bool> done{false};
    std::thread watcher([&] {
      service::Client w(client_options(srv.address(), ""));
      while (!done) {
        if (w.get(id).state() == v1::CANCELLED) {
          ++seen;
          unlogged += read_text(state / "logs" / (id + ".log")).find(" cancelled: ") == std::string::npos;
          return;
        }
      }
    });
    c.cancel(id);
    std::this_thread::sleep_for(50ms);
    done = true;
    watcher.join();
  }
  c.cancel(blocker);
  EXPECT_EQ(seen, 8);
  EXPECT_EQ(unlogged, 0);
  std::printf("reliability: queued jobs cancelled 8, seen cancelled %d, of which without the log line %d\n", seen, unlogged);
}

// SIGTERM after 50 MB of downloads, with one more fetch in progress whose client has stopped
// reading, stops the server within its documented time, and the state directory is free for the
// next server at once.
TEST(Reliability, StopAfterALargeFetchIsQuick) {
  TempDir d;
  const fs::path state = d.p / "state";
  auto srv = std::make_unique<ServerProcess>(state, std::vector<std::string>{"--data-root", kScenarios});
  std::int64_t fetched = 0;
  service::Client c(client_options(srv->address(), ""));
  auto s = arelen(15, 600, 0);
  s.mutable_outputs()->set_timeseries_interval_s(1);
  const std::string id = c.submit(s).id();
  ASSERT_EQ(c.watch(id).state(), v1::SUCCEEDED);
  const auto listed = c.results(id);
  v1::ResultFile biggest;
  for (const auto& f : listed.files()) {  // every result, then the largest again up to 50 MB
    c.download(id, f.name(), (d.p / "fetched").string());
    fetched += f.bytes();
    if (f.bytes() > biggest.bytes()) biggest = f;
  }
  for (; fetched < 50'000'000; fetched += biggest.bytes()) c.download(id, biggest.name(), (d.p / "fetched").string());
  // A second fetch, stopped (SIGSTOP) while it downloads: its stream stalls in the server.
  const fs::path pid_file = d.p / "fetch.pid";
  ASSERT_EQ(std::system((runout_binary() + " fetch " + id + " --server " + srv->address() + " --out " + (d.p / "stalled").string() +
                         " > /dev/null 2>&1 & echo $! > " + pid_file.string()).c_str()), 0);
  const pid_t fetcher = pid_t(std::atol(read_text(pid_file).c_str()));
  auto partial_bytes = [&] {  // what the fetch has written so far (beside its --out folder)
    std::int64_t n = 0;
    std::error_code ec;
    for (const auto& e : fs::recursive_directory_iterator(d.p, ec))
      if (e.path().string().find("stalled") != std::string::npos && e.is_regular_file(ec)) n += std::int64_t(e.file_size(ec));
    return n;
  };
  ASSERT_TRUE(wait_for([&] { return partial_bytes() > 0; }, 20s)) << "the second fetch never started";
  kill(fetcher, SIGSTOP);
  ASSERT_FALSE(fs::exists(d.p / "stalled")) << "the second fetch ended before it was stopped: nothing stalled";
  const auto t0 = std::chrono::steady_clock::now();
  const int st = srv->stop(SIGTERM);
  const double stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  kill(fetcher, SIGKILL);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << st;
  EXPECT_LT(stop_s, 2.0) << "operations.md: the server stops within 2 s; its log:\n" << srv->log().substr(srv->log().size() > 600 ? srv->log().size() - 600 : 0);
  srv = std::make_unique<ServerProcess>(state, std::vector<std::string>{"--data-root", kScenarios});
  EXPECT_TRUE(srv->running()) << "the next server on the state directory: " << srv->errors();
  std::printf("reliability: stopped %.2f s after %.1f MB fetched, with a stalled fetch in progress; the next server started\n", stop_s,
              double(fetched) / 1e6);
}

namespace {

// A one-polygon shapefile without .prj (a local CRS).
void local_polygon(const fs::path& path, double x0, double y0, double x1, double y1) {
  GDALAllRegister();
  GDALDatasetUniquePtr ds(GetGDALDriverManager()->GetDriverByName("ESRI Shapefile")->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  ASSERT_TRUE(ds);
  auto* layer = ds->CreateLayer("release", nullptr, wkbPolygon, nullptr);
  OGRFeature f(layer->GetLayerDefn());
  OGRLinearRing ring;
  for (auto [x, y] : std::vector<std::pair<double, double>>{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}}) ring.addPoint(x, y);
  OGRPolygon p;
  p.addRing(&ring);
  f.SetGeometry(&p);
  ASSERT_EQ(layer->CreateFeature(&f), OGRERR_NONE);
}

// A local-CRS scenario on `dem` with the release `rel`, Coulomb 20 deg, 120 s.
fs::path local_scenario(const fs::path& dir, const std::string& name, const fs::path& dem, const fs::path& rel) {
  auto s = arelen(20, 120);
  s.set_name(name);
  s.mutable_dem()->set_path(dem.string());
  s.mutable_dem()->set_crs("local");
  s.clear_area_of_interest();
  s.mutable_grid()->set_resolution_m(0);
  s.mutable_grid()->set_crs("dem");
  auto* r = s.mutable_releases(0);
  r->set_path(rel.string());
  r->set_crs("local");
  r->clear_thickness_attribute();
  r->clear_min_slope_attribute();
  r->clear_max_slope_attribute();
  r->set_thickness_m(2);
  return scenario_file(s, dir, name);
}

}  // namespace

// What the reader of the maps must know is in run.json and on the maps: a release polygon partly
// outside the domain (clipped), and near-vertical cells under the release or the flow.
TEST(Reliability, ClippedReleasesAndNearVerticalTerrainAreNoted) {
  TempDir d;
  // A 35 deg slope falling east, 600 m x 400 m at 5 m, with a 200 m cliff at x = 300 m.
  const int nx = 120, ny = 80;
  std::vector<double> cliff(std::size_t(nx) * ny), plain(cliff.size());
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) {
      const double x = (i + 0.5) * 5;
      plain[std::size_t(r) * nx + i] = 1000 - std::tan(35 * M_PI / 180) * x;
      cliff[std::size_t(r) * nx + i] = plain[std::size_t(r) * nx + i] - (x > 300 ? 200 : 0);
    }
  write_local_raster((d.p / "cliff.tif").string(), nx, ny, 0, 400, 5, cliff);
  write_local_raster((d.p / "plain.tif").string(), nx, ny, 0, 400, 5, plain);
  local_polygon(d.p / "inside.shp", 100, 150, 200, 250);
  local_polygon(d.p / "half.shp", -100, 150, 100, 250);  // half of it west of the DEM
  struct Case {
    const char* what;
    const char* dem;
    const char* rel;
    const char* release_note;  // "" for none
    const char* note;          // in run.json's notes ("" for none)
  };
  const std::vector<Case> cases = {
      {"plain slope", "plain.tif", "inside.shp", "", ""},
      {"clipped release", "plain.tif", "half.shp", "50.0 % of its area (10000 of 20000 m2) lies outside the grid", ""},
      {"cliff", "cliff.tif", "inside.shp", "", "near-vertical terrain: 0 cell(s) of the release and"},
  };
  int noted = 0, n = 0;
  for (const auto& k : cases) {
    const std::string name = "case-" + std::to_string(n++);
    const fs::path out = d.p / ("out-" + name);
    const auto file = local_scenario(d.p, name, d.p / k.dem, d.p / k.rel);
    const auto ran = run_cli("run " + file.string() + " --out " + out.string() + " --quiet", d.p);
    ASSERT_EQ(ran.code, 0) << k.what << ": " << ran.err;
    google::protobuf::Value v;
    ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(run_json_text(out), &v).ok()) << k.what;
    const auto& f = v.struct_value().fields();
    std::string release_notes, notes;
    for (const auto& n : f.at("release").struct_value().fields().at("notes").list_value().values()) release_notes += n.string_value() + "\n";
    if (f.count("notes"))
      for (const auto& n : f.at("notes").list_value().values()) notes += n.string_value() + "\n";
    if (*k.release_note) {
      EXPECT_NE(release_notes.find(k.release_note), std::string::npos) << k.what << ": " << release_notes;
      noted += release_notes.find(k.release_note) != std::string::npos;
    } else {
      EXPECT_EQ(release_notes.find("outside"), std::string::npos) << k.what << ": " << release_notes;
    }
    if (*k.note) {
      EXPECT_NE(notes.find(k.note), std::string::npos) << k.what << ": " << notes;
      EXPECT_NE(notes.find("before using the maps there\n"), std::string::npos) << k.what << ": the note is cut short: " << notes;
      noted += notes.find(k.note) != std::string::npos;
    } else {
      EXPECT_EQ(notes.find("near-vertical"), std::string::npos) << k.what << ": " << notes;
    }
  }
  EXPECT_EQ(noted, 2);
  std::printf("reliability: a release half outside the DEM and a flow over a 200 m cliff: noted %d of 2 in run.json\n", noted);
}
