#pragma once
// Test support for the fault-injection suite (tests/reliability/): scenarios, the bitwise
// fingerprint of a run's results, status codes and waiting.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/statvfs.h>
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

#include "jobs/scenario/scenario.hpp"
#include "jobs/digest/sha256.hpp"
#include "jobs/system/store.hpp"
#include "terrain/terrain.hpp"
#include "tests/support/server_process.hpp"


namespace runout::test_support::reliability {

namespace fs = std::filesystem;
using namespace runout;
using namespace std::chrono_literals;
using test_support::client_options;
using test_support::read_text;
using test_support::runout_binary;
using test_support::ServerOptions;
using test_support::ServerProcess;
using test_support::TempDir;


inline const std::string kSource = RUNOUT_SOURCE_DIR;
inline const std::string kScenarios = kSource + "/scenarios";

// In den Arelen at 30 m with its inputs named relative to the scenarios folder (a data root).
inline v1::Scenario arelen(double bed_friction = 15, double end_time = 600, double stop_fraction = 0.01) {
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
inline v1::Scenario coarse_collapse() {
  auto lab = jobs::load_scenario(kScenarios + "/lab/b2-collapse-0deg.json").scenario;
  lab.mutable_lab()->set_nx(100);
  lab.mutable_lab()->set_ny(30);
  lab.mutable_lab()->set_end_time_s(1.0);
  return lab;
}

// The scenario as a file for `runout run`, its inputs by absolute path.
inline fs::path scenario_file(const v1::Scenario& s0, const fs::path& dir, const std::string& name) {
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
inline std::map<std::string, std::string> h5_datasets(const fs::path& file) {
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
inline void flatten(const google::protobuf::Value& v, const std::string& path, std::map<std::string, std::string>& out) {
  if (v.has_struct_value()) {
    for (const auto& [k, x] : v.struct_value().fields()) flatten(x, path.empty() ? k : path + "." + k, out);
    return;
  }
  if (v.has_list_value()) {  // element by element: a struct's keys come out of JSON in no fixed order
    for (int k = 0; k < v.list_value().values_size(); ++k) flatten(v.list_value().values(k), path + "[" + std::to_string(k) + "]", out);
    out[path + ".size"] = std::to_string(v.list_value().values_size());
    return;
  }
  std::string j;
  (void)google::protobuf::util::MessageToJsonString(v, &j);
  out[path] = j;
}

inline std::map<std::string, std::string> figures(const fs::path& run_json) {
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
inline std::map<std::string, std::string> fingerprint(const fs::path& dir) {
  std::map<std::string, std::string> fp;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string(), ext = e.path().extension().string();
    if (ext == ".tif" || n == "outline.geojson") fp[n] = jobs::sha256_file(e.path().string());
    if (ext == ".h5")
      for (const auto& [k, v] : h5_datasets(e.path())) fp[n + ":" + k] = v;
    if (n == "run.json")
      for (const auto& [k, v] : figures(e.path())) fp[n + ":" + k] = v;
  }
  return fp;
}

// A file of `bytes` random bytes (from `seed`): content no format reads, and no upload repeats.
inline void write_random_file(const fs::path& p, std::size_t bytes, unsigned seed) {
  std::mt19937 rng(seed);
  std::string b(bytes, '\0');
  for (auto& c : b) c = char(rng());
  std::ofstream(p, std::ios::binary) << b;
}

inline int code_of(const std::function<void()>& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const service::RpcError& e) {
    if (message) *message = e.what();
    return e.code;
  }
  return 0;
}

inline std::string code_name(int c) {
  static const char* names[] = {"OK", "CANCELLED", "UNKNOWN", "INVALID_ARGUMENT", "DEADLINE_EXCEEDED", "NOT_FOUND", "ALREADY_EXISTS",
                                "PERMISSION_DENIED", "RESOURCE_EXHAUSTED", "FAILED_PRECONDITION", "ABORTED", "OUT_OF_RANGE",
                                "UNIMPLEMENTED", "INTERNAL", "UNAVAILABLE", "DATA_LOSS", "UNAUTHENTICATED"};
  return c >= 0 && c <= 16 ? names[c] : std::to_string(c);
}

inline bool wait_for(const std::function<bool()>& cond, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (cond()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return cond();
}

// The pid of the job's current worker process, from its log ("worker process PID").
inline pid_t worker_pid(const fs::path& state, const std::string& id) {
  const std::string log = read_text(state / "logs" / (id + ".log"));
  const auto k = log.rfind("worker process ");
  if (k == std::string::npos) return -1;
  return pid_t(std::atol(log.c_str() + k + 15));
}


}  // namespace runout::test_support::reliability
