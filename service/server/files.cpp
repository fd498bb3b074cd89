// Files: uploads (quota, time to live, collection) and results (listing, download).
#include "service/server/impl.hpp"
#include "jobs/scenario/inputs.hpp"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <gdal.h>
#include <openssl/crypto.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstring>
#include <set>
#include <ctime>
#include <cmath>
#include <thread>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include "jobs/scenario/scenario.hpp"
#include "jobs/system/scheduler.hpp"
#include "jobs/digest/sha256.hpp"
#include "jobs/system/state_dir.hpp"
#include "jobs/system/worker.hpp"
#include "runout/v1/worker.pb.h"
#include "jobs/system/store.hpp"
#include "runout/v1/service.grpc.pb.h"
#include "service/server/inputs.hpp"
#include "service/server/tokens.hpp"

namespace fs = std::filesystem;

namespace runout::service {

// The uploads a scenario names (their ids), from its resolved paths.
std::vector<std::string> Server::Impl::uploads_of(const v1::Scenario& s) const {
  std::vector<std::string> ids;
  const std::string up = (fs::path(cfg.state_dir()) / "uploads").string() + "/";
  auto take = [&](const std::string& p) {
    if (p.rfind(up, 0) == 0) ids.push_back(p.substr(up.size(), 64));
  };
  v1::Scenario paths = s;
  jobs::for_each_input_path(paths, [&](const std::string&, std::string* p) { take(*p); });
  return ids;
}

// Remove uploads that nothing uses: no queued or running job, no submission in progress. `owner`
// given: the uploads of that client's refused submission (its record of them is dropped, and a
// folder goes only when no client holds a record of it); else all whose last use is older than
// the upload time-to-live.
void Server::Impl::collect_uploads(const std::vector<std::string>& only, const std::string& owner) {
  std::lock_guard lk(upload_mu);
  std::set<std::string> used;
  for (const auto& j : store->active_jobs())
    for (const auto& id : uploads_of(j.scenario)) used.insert(id);
  for (const auto& [id, n] : uploads_in_flight)
    if (n > 0) used.insert(id);
  std::set<std::string> drop;
  if (!owner.empty()) {
    for (const auto& id : only)
      if (!store->forget_upload(id, owner)) drop.insert(id);
  } else {
    const double cutoff = double(std::time(nullptr)) - cfg.upload_ttl_s();
    for (const auto& id : store->uploads_older_than(cutoff)) drop.insert(id);
    const auto all = store->uploads_older_than(1e18);
    const std::set<std::string> recorded(all.begin(), all.end());
    std::error_code ec;  // folders without a record (a store rebuilt by --recover): by their time
    for (const auto& e : fs::directory_iterator(fs::path(cfg.state_dir()) / "uploads", ec)) {
      const std::string id = e.path().filename().string();
      if (!is_hex64(id) || recorded.count(id)) continue;
      std::error_code ec2;
      const auto mt = fs::last_write_time(e.path(), ec2);
      const double age = std::chrono::duration<double>(fs::file_time_type::clock::now() - mt).count();
      if (!ec2 && age > cfg.upload_ttl_s()) drop.insert(id);
    }
  }
  for (const auto& id : drop) {
    if (used.count(id)) continue;
    // The record first, then the folder: whoever sees the folder gone sees its bytes off the quota
    // (a crash in between leaves a folder without a record, collected by its age above).
    store->forget_upload(id);
    std::error_code ec;
    fs::remove_all(fs::path(cfg.state_dir()) / "uploads" / id, ec);
    log("upload " + id.substr(0, 12) + " removed (" +
        (owner.empty() ? "unused for longer than the upload time-to-live" : "its submission was refused") + ")");
  }
}

// The files of a job the client may download: the results of a succeeded job, those of its folders
// one level down as "FOLDER/NAME" (a nest's 3D run: nest/run.json), and its log. A download names
// one of these exactly, so no other path is reachable.
std::vector<v1::ResultFile> Server::Impl::result_files(const jobs::StoredJob& j) {
  std::vector<v1::ResultFile> out;
  std::error_code ec;
  if (j.job.state() == v1::SUCCEEDED && !j.results_removed) {
    const fs::path d = sched->results_dir(j.job.scenario_hash());
    std::function<void(const fs::path&, const std::string&)> list = [&](const fs::path& dir, const std::string& prefix) {
      for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (e.is_symlink(ec)) continue;
        if (e.is_directory(ec)) {  // one level down only, not a hidden folder
          if (prefix.empty() && !name.empty() && name[0] != '.') list(e.path(), name + "/");
        } else if (e.is_regular_file(ec)) {
          v1::ResultFile f;
          f.set_name(prefix + name);
          f.set_bytes(std::int64_t(e.file_size(ec)));
          out.push_back(f);
        }
      }
    };
    list(d, "");
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.name() < b.name(); });
  }
  const fs::path lg = sched->log_path(j.job.id());
  if (fs::exists(lg, ec)) {
    v1::ResultFile f;
    f.set_name("job.log");
    f.set_bytes(std::int64_t(public_log(j.job.id()).size()));
    out.push_back(f);
  }
  return out;
}

Status Server::Impl::ListResults(grpc::ServerContext* ctx, const v1::ListResultsRequest* req, v1::ListResultsResponse* resp) {
  std::string owner;
  if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
  const auto j = store->get(req->job_id(), owner);
  if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->job_id() + "'"};
  for (auto& f : result_files(*j)) *resp->add_files() = f;  // after retention: the log only
  return Status::OK;
}

Status Server::Impl::DownloadResult(grpc::ServerContext* ctx, const v1::DownloadResultRequest* req, grpc::ServerWriter<v1::DataChunk>* w) {
  std::string owner;
  if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
  const auto j = store->get(req->job_id(), owner);
  if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->job_id() + "'"};
  const auto files = result_files(*j);
  const bool listed = std::any_of(files.begin(), files.end(), [&](const auto& f) { return f.name() == req->name(); });
  if (!listed) {
    if (j->job.state() == v1::SUCCEEDED && j->results_removed && req->name() != "job.log")
      return {StatusCode::FAILED_PRECONDITION, "the results of job " + j->job.id() + " were removed by the retention policy"};
    if (j->job.state() != v1::SUCCEEDED && req->name() != "job.log")
      return {StatusCode::FAILED_PRECONDITION,
              "job " + j->job.id() + " is " + jobs::state_name(j->job.state()) + ": only job.log can be fetched"};
    return {StatusCode::NOT_FOUND, "job " + j->job.id() + " has no result '" + req->name() + "'"};
  }
  std::unique_ptr<std::istream> src;
  std::int64_t total = 0;
  if (req->name() == "job.log") {
    const std::string text = public_log(j->job.id());
    total = std::int64_t(text.size());
    src = std::make_unique<std::istringstream>(text);
  } else {
    const fs::path p = fs::path(sched->results_dir(j->job.scenario_hash())) / req->name();
    src = std::make_unique<std::ifstream>(p, std::ios::binary);
    if (!*src) return {StatusCode::INTERNAL, "cannot read result '" + req->name() + "'"};
    std::error_code ec;
    total = std::int64_t(fs::file_size(p, ec));
  }
  auto& in = *src;
  jobs::Sha256 h;
  std::string buf(256 << 10, '\0');  // well below the smallest message limit
  std::int64_t offset = 0;
  bool first = true;
  for (;;) {
    in.read(buf.data(), std::streamsize(buf.size()));
    const auto n = std::size_t(in.gcount());
    const bool last = !in || offset + std::int64_t(n) >= total;
    v1::DataChunk c;
    c.set_data(buf.data(), n);
    c.set_offset(offset);
    h.update(std::string_view(buf.data(), n));
    if (first) c.set_total_bytes(total);
    if (last) c.set_sha256(h.hex());
    if (!w->Write(c)) return {StatusCode::CANCELLED, "the client went away"};
    {
      std::lock_guard lk(stop_mu);  // a stop ends a download between chunks
      if (stopped) return {StatusCode::UNAVAILABLE, "the server is stopping; fetch again when it is back"};
    }
    offset += std::int64_t(n);
    first = false;
    if (last) break;
  }
  return Status::OK;
}

Status Server::Impl::UploadInput(grpc::ServerContext* ctx, grpc::ServerReader<v1::UploadChunk>* r, v1::UploadResponse* resp) {
  std::string owner;
  if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
  const fs::path up = fs::path(cfg.state_dir()) / "uploads";
  const fs::path tmp = up / (".tmp-" + jobs::new_job_id());
  std::error_code ec;
  fs::create_directories(tmp, ec);
  if (ec) return {StatusCode::INTERNAL, "cannot create an upload folder: " + ec.message()};
  auto fail = [&](StatusCode c, const std::string& m) {
    fs::remove_all(tmp, ec);
    return Status(c, m);
  };
  v1::UploadChunk c;
  std::string current;
  std::ofstream out;
  std::vector<std::string> names;
  jobs::Sha256 set_hash;
  std::unique_ptr<jobs::Sha256> file_hash;
  std::int64_t bytes = 0;
  // This upload's bytes count against the client's quota while they arrive, so that uploads of one
  // client at once cannot together exceed it.
  struct Arriving {
    Impl& m;
    const std::string& owner;
    std::int64_t bytes = 0;
    bool take(std::int64_t n, std::int64_t quota) {
      std::lock_guard lk(m.upload_mu);
      auto& total = m.bytes_arriving[owner];
      if (m.store->upload_bytes(owner) + total + n > quota) return false;
      total += n;
      bytes += n;
      return true;
    }
    ~Arriving() {
      std::lock_guard lk(m.upload_mu);
      if ((m.bytes_arriving[owner] -= bytes) <= 0) m.bytes_arriving.erase(owner);
    }
  } arriving{*this, owner};
  auto close_file = [&] {
    if (!current.empty()) {
      out.close();
      set_hash.update(current + "\n" + file_hash->hex() + "\n");
    }
  };
  while (r->Read(&c)) {
    if (c.file_name() != current && !c.file_name().empty() && names.size() >= 16)
      return fail(StatusCode::INVALID_ARGUMENT, "an upload holds at most 16 files (one input and its companions)");
    if (c.file_name() != current && !c.file_name().empty()) {
      if (!plain_name(c.file_name()))
        return fail(StatusCode::INVALID_ARGUMENT, "file_name: '" + c.file_name() + "' must be a plain file name (letters, digits, . _ -)");
      if (std::find(names.begin(), names.end(), c.file_name()) != names.end())
        return fail(StatusCode::INVALID_ARGUMENT, "file_name: '" + c.file_name() + "' sent twice in one upload");
      close_file();
      current = c.file_name();
      names.push_back(current);
      out.open(tmp / current, std::ios::binary);
      file_hash = std::make_unique<jobs::Sha256>();
    }
    if (current.empty()) return fail(StatusCode::INVALID_ARGUMENT, "file_name: the first chunk must name its file");
    bytes += std::int64_t(c.data().size());
    if (bytes > cfg.max_upload_bytes())
      return fail(StatusCode::RESOURCE_EXHAUSTED, "upload larger than the server's limit of " + std::to_string(cfg.max_upload_bytes()) + " bytes");
    if (!arriving.take(std::int64_t(c.data().size()), cfg.max_upload_bytes_per_client()))
      return fail(StatusCode::RESOURCE_EXHAUSTED,
                  "this client's uploads would exceed its quota of " + std::to_string(cfg.max_upload_bytes_per_client()) +
                      " bytes (uploads no queued or running job uses are removed after " + jobs::json_number(cfg.upload_ttl_s()) + " s)");
    errno = 0;
    out.write(c.data().data(), std::streamsize(c.data().size()));
    file_hash->update(c.data());
    if (!out)
      return fail(errno == ENOSPC ? StatusCode::RESOURCE_EXHAUSTED : StatusCode::INTERNAL,
                  std::string("writing the upload failed: ") + (errno ? std::strerror(errno) : "write error") +
                      (errno == ENOSPC ? " (the server's disk is full)" : ""));
  }
  if (ctx->IsCancelled()) return fail(StatusCode::CANCELLED, "the client went away during the upload");
  if (names.empty()) return fail(StatusCode::INVALID_ARGUMENT, "empty upload");
  close_file();
  const std::string id = set_hash.hex();
  const fs::path dest = up / id;
  // Not while the collector decides. Declared after `arriving`, so released before ~Arriving locks
  // upload_mu again.
  std::lock_guard ulk(upload_mu);
  if (fs::exists(dest, ec)) {
    fs::remove_all(tmp, ec);  // the same files were uploaded before
    fs::last_write_time(dest, fs::file_time_type::clock::now(), ec);
  } else {
    fs::rename(tmp, dest, ec);
    if (ec && !fs::exists(dest)) return fail(StatusCode::INTERNAL, "storing the upload failed: " + ec.message());
    fs::remove_all(tmp, ec);
  }
  store->record_upload(owner, id, bytes);
  resp->set_ref("upload:" + id + "/" + names.front());
  for (const auto& n : names) resp->add_files(n);
  resp->set_bytes(bytes);
  log("upload " + id.substr(0, 12) + " (" + owner + "): " + std::to_string(names.size()) + " file(s), " + std::to_string(bytes) + " bytes");
  return Status::OK;
}

}  // namespace runout::service
