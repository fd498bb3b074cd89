#include "service/server/inputs.hpp"

#include <gdal.h>
#include <signal.h>
#include <sys/statvfs.h>

#include <chrono>
#include <fstream>
#include <optional>
#include <sstream>

#include "jobs/system/scheduler.hpp"
#include "jobs/system/store.hpp"
#include "jobs/system/worker.hpp"
#include "runout/v1/worker.pb.h"
#include "service/server/server.hpp"

namespace fs = std::filesystem;

namespace runout::service {

using grpc::Status;
using grpc::StatusCode;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError("cannot read '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool is_hex64(const std::string& s) {
  return s.size() == 64 && s.find_first_not_of("0123456789abcdefABCDEF") == std::string::npos;
}

bool plain_name(const std::string& n) {
  if (n.empty() || n.size() > 200 || n[0] == '.') return false;
  return n.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") == std::string::npos;
}

bool inside(const fs::path& p, const fs::path& root) {
  auto r = root.begin(), q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    if (r->empty()) continue;  // a trailing separator
    if (q == p.end() || *q != *r) return false;
  }
  return true;
}


grpc::Status full_disk(const v1::ServerConfig& cfg, const std::string& why) {
  struct statvfs v {};
  if (::statvfs(cfg.state_dir().c_str(), &v) != 0) return Status::OK;
  const std::int64_t left = std::int64_t(v.f_bavail) * std::int64_t(v.f_frsize);
  if (left >= kMinFreeBytes && (why.empty() || left >= 4 * kMinFreeBytes)) return Status::OK;
  return {StatusCode::RESOURCE_EXHAUSTED, "the server's disk is full (" + std::to_string(left >> 10) + " KiB free)" +
                                              (why.empty() ? "" : ": " + why) + "; try again when its operator has freed space"};
}

// A scenario's input path on this server: an uploaded file or a file inside a data root.
Status resolve_input(const v1::ServerConfig& cfg, const std::string& field, std::string* path) {
  const std::string p = *path;
  if (p.empty()) return Status::OK;  // the scenario's own check names what is missing
  if (p.rfind("upload:", 0) == 0) {
    const std::string ref = p.substr(7);
    const auto slash = ref.find('/');
    const std::string id = ref.substr(0, slash), name = slash == std::string::npos ? "" : ref.substr(slash + 1);
    if (!is_hex64(id) || !plain_name(name))
      return {StatusCode::INVALID_ARGUMENT, field + ": '" + p + "' is not an upload reference (upload:ID/NAME)"};
    const fs::path f = fs::path(cfg.state_dir()) / "uploads" / id / name;
    if (!fs::is_regular_file(f))
      return {StatusCode::NOT_FOUND, field + ": no upload '" + p +
                                         "' on this server (uploads go when a submission that names them is refused, and when unused past their "
                                         "time to live): upload the file again"};
    *path = f.string();
    return allowed_format(field, *path);
  }
  if (cfg.data_roots().empty())
    return {StatusCode::INVALID_ARGUMENT,
            field + ": '" + p + "': this server has no data roots; upload the file (runout submit does) and use its upload: reference"};
  for (const auto& part : fs::path(p))
    if (part == "..") return {StatusCode::INVALID_ARGUMENT, field + ": '" + p + "' may not contain '..'"};
  // One answer for every refusal, so that it tells nothing about files outside the roots.
  const Status refused{StatusCode::INVALID_ARGUMENT, field + ": '" + p + "' is not a readable file inside the server's data roots"};
  std::error_code ec;
  for (const auto& root : cfg.data_roots()) {
    const fs::path cand = (fs::path(p).is_absolute() ? fs::path(p) : fs::path(root) / p).lexically_normal();
    if (!inside(cand, root)) continue;  // checked before the file system is asked anything
    const fs::path real = fs::canonical(cand, ec);  // symbolic links resolved
    if (ec) continue;
    bool ok = false;
    for (const auto& r : cfg.data_roots()) ok |= inside(real, r);
    if (!ok || !fs::is_regular_file(real, ec)) return refused;
    *path = real.string();
    return allowed_format(field, *path);
  }
  return refused;
}

// Only formats that cannot point at other files or URLs (no VRT, no /vsi paths inside).
Status allowed_format(const std::string& field, const std::string& path) {
  static const char* const kAllowed[] = {"GTiff", "COG", "AAIGrid", "SRTMHGT", "EHdr", "GeoJSON", "ESRI Shapefile", "GPKG", nullptr};
  GDALDriverH d = GDALIdentifyDriverEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_VECTOR, kAllowed, nullptr);
  if (!d)
    return {StatusCode::INVALID_ARGUMENT, field + ": '" + fs::path(path).filename().string() +
                                              "' is not in a format this server reads (GeoTIFF, ESRI ASCII grid, SRTM .hgt, "
                                              "EHdr, GeoJSON, Shapefile, GeoPackage)"};
  return Status::OK;
}

// Every check `runout run` makes, in a worker process of its own (a DEM that crashes or hangs
// GDAL takes only that process down): the inputs read, the grid or mesh built, one step run.
Status check_in_worker(const v1::ServerConfig& cfg, const v1::Scenario& s, const std::function<void(const std::string&)>& log,
                       const std::function<bool()>& stop) {
  const fs::path dir = fs::path(cfg.state_dir()) / "validate" / jobs::new_job_id();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return {StatusCode::INTERNAL, "cannot create a folder to check the scenario in: " + ec.message()};
  v1::WorkerTask task;
  task.set_job_id("validate");
  *task.mutable_scenario() = s;
  task.set_out_dir(dir.string());
  task.set_threads(1);
  task.set_validate_only(true);
  Status st = Status::OK;
  try {
    jobs::WorkerProcess w(jobs::self_executable(), task, (dir / "validate.log").string());
    std::optional<v1::WorkerEvent> outcome;
    const auto t0 = std::chrono::steady_clock::now();
    bool timed_out = false, too_big = false, stopped = false;
    for (;;) {  // every event, also those read with the end of the output
      auto ev = w.next_event(std::chrono::milliseconds(100));
      if (!ev && w.output_closed()) break;
      if (stop && stop()) {
        stopped = true;
        w.signal(SIGKILL);
        break;
      }
      if (ev && !ev->has_progress()) outcome = ev;
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (wall > kValidateSeconds || (cfg.max_job_memory_bytes() > 0 && w.resident_bytes() > cfg.max_job_memory_bytes())) {
        timed_out = wall > kValidateSeconds;
        too_big = !timed_out;
        w.signal(SIGKILL);
        break;
      }
    }
    auto ex = w.wait(std::chrono::seconds(10));
    if (!ex) {
      w.signal(SIGKILL);
      ex = w.wait(std::chrono::seconds(60));
    }
    if (stopped) {
      st = {StatusCode::UNAVAILABLE, "the server is stopping; submit again when it is back"};
    } else if (outcome && outcome->has_failed()) {
      const std::string m = jobs::client_message(outcome->failed().error(), cfg.state_dir(),
                                                 {cfg.data_roots().begin(), cfg.data_roots().end()});
      st = outcome->failed().bad_input() ? Status(StatusCode::INVALID_ARGUMENT, m)
                                         : Status(StatusCode::INVALID_ARGUMENT, "checking the scenario failed: " + m);
    } else if (!outcome && timed_out) {
      log("checking a scenario took longer than " + std::to_string(int(kValidateSeconds)) +
          " s; accepted, its remaining checks run with the job");
    } else if (!outcome && too_big) {
      st = {StatusCode::INVALID_ARGUMENT, "checking the scenario needed more than the server's memory limit for a job (" +
                                              std::to_string(cfg.max_job_memory_bytes() >> 20) + " MiB): coarsen it"};
    } else if (!outcome && ex && ex->exited && ex->code == 127) {
      log("cannot start a worker process (" + jobs::self_executable() + " worker): exit status 127");
      st = {StatusCode::INTERNAL, "the server cannot start its worker processes (its log says more)"};
    } else if (!outcome) {
      st = {StatusCode::INVALID_ARGUMENT, "checking the scenario's inputs ended the checking process (" +
                                              (ex ? ex->describe() : std::string("no exit status")) +
                                              "): the inputs cannot be read safely"};
    }
  } catch (const std::exception& e) {
    st = {StatusCode::INTERNAL, std::string("cannot check the scenario: ") + e.what()};
  }
  fs::remove_all(dir, ec);
  return st;
}

}  // namespace runout::service
