// The fault-injection suite (ctest label `reliability`), what clients send: concurrent duplicated
// request ids, bad scenarios at the door, a bounded fuzz run, upload quota and collection. Each test
// starts its own `runout serve` on loopback and prints a `reliability:` line with its figures.
#include "tests/support/reliability_helpers.hpp"

using namespace runout::test_support::reliability;

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
      {"3D engine with a Voellmy material",
       [](v1::Scenario& s) {
         s.set_engine("vof");
         s.mutable_material()->set_rheology("voellmy");
       },
       bad, "material.rheology"},
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
