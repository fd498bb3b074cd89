#include "service/server/server.hpp"

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
#include "terrain/terrain.hpp"

namespace fs = std::filesystem;

namespace runout::service {

namespace {

using grpc::Status;
using grpc::StatusCode;

}  // namespace

struct Server::Impl final : v1::Runout::Service {
  v1::ServerConfig cfg;
  std::unique_ptr<jobs::StateLock> lock;
  bool recover = false;    // rebuild a lost store at start (`runout serve --recover`)
  std::string recovery;    // what the rebuilding did
  std::thread housekeeping;
  std::condition_variable housekeeping_cv;
  std::unique_ptr<Tokens> tokens;
  std::unique_ptr<jobs::JobStore> store;
  std::unique_ptr<jobs::Scheduler> sched;
  std::unique_ptr<grpc::Server> server;
  int bound_port = 0;
  std::mutex log_mu;
  std::mutex upload_mu;
  std::map<std::string, int> uploads_in_flight;  // guarded by upload_mu
  std::mutex validate_mu;
  std::condition_variable validate_cv;
  int validating = 0;
  std::ofstream log_file;
  std::mutex stop_mu;
  std::condition_variable stop_cv;
  bool stopped = false;

  void log(const std::string& line) {
    std::lock_guard lk(log_mu);
    std::ostream& o = log_file.is_open() ? static_cast<std::ostream&>(log_file) : std::cerr;
    o << jobs::utc_now() << " " << line << std::endl;
  }

  Status authenticate(grpc::ServerContext* ctx, std::string* owner) {
    if (!tokens->enabled()) {
      *owner = "local";
      return Status::OK;
    }
    const auto& md = ctx->client_metadata();
    const auto it = md.find("authorization");
    if (it == md.end()) return {StatusCode::UNAUTHENTICATED, "missing bearer token (metadata 'authorization: Bearer TOKEN')"};
    const std::string v(it->second.data(), it->second.size());
    if (v.rfind("Bearer ", 0) != 0) return {StatusCode::UNAUTHENTICATED, "the authorization metadata must read 'Bearer TOKEN'"};
    *owner = tokens->owner_of(v.substr(7));
    if (owner->empty()) return {StatusCode::UNAUTHENTICATED, "unknown bearer token"};
    return Status::OK;
  }

  v1::Job with_live(const jobs::StoredJob& j) {
    v1::Job out = j.job;
    const auto l = sched->live(j.job.id());
    if (l.running && out.state() == v1::RUNNING) *out.mutable_progress() = l.progress;
    return out;
  }

  // The uploads a scenario names (their ids), from its resolved paths.
  std::vector<std::string> uploads_of(const v1::Scenario& s) const {
    std::vector<std::string> ids;
    const std::string up = (fs::path(cfg.state_dir()) / "uploads").string() + "/";
    auto take = [&](const std::string& p) {
      if (p.rfind(up, 0) == 0) ids.push_back(p.substr(up.size(), 64));
    };
    take(s.dem().path());
    take(s.area_of_interest().path());
    for (const auto& r : s.releases()) take(r.path());
    return ids;
  }

  // Remove uploads that nothing uses: no queued or running job, no submission in progress. `owner`
  // given: the uploads of that client's refused submission (its record of them is dropped, and a
  // folder goes only when no client holds a record of it); else all whose last use is older than
  // the upload time-to-live.
  void collect_uploads(const std::vector<std::string>& only = {}, const std::string& owner = "") {
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
      std::error_code ec;
      fs::remove_all(fs::path(cfg.state_dir()) / "uploads" / id, ec);
      store->forget_upload(id);
      log("upload " + id.substr(0, 12) + " removed (" +
          (owner.empty() ? "unused for longer than the upload time-to-live" : "its submission was refused") + ")");
    }
  }

  // Uploads a submission in progress uses: not collected meanwhile.
  struct InFlight {
    Impl& m;
    std::vector<std::string> ids;
    void take(const std::string& id) {
      std::lock_guard lk(m.upload_mu);
      ++m.uploads_in_flight[id];
      ids.push_back(id);
    }
    void release() {
      std::lock_guard lk(m.upload_mu);
      for (const auto& id : ids)
        if (--m.uploads_in_flight[id] <= 0) m.uploads_in_flight.erase(id);
      ids.clear();
    }
    ~InFlight() { release(); }
  };

  // At most this many checks of submissions at once (each a process that may use a job's memory).
  bool enter_validation() {
    std::unique_lock lk(validate_mu);
    const int limit = std::max(2, cfg.workers());
    if (!validate_cv.wait_for(lk, std::chrono::seconds(60), [&] { return validating < limit; })) return false;
    ++validating;
    return true;
  }
  void leave_validation() {
    {
      std::lock_guard lk(validate_mu);
      --validating;
    }
    validate_cv.notify_one();
  }


  // The digest of a submitted scenario as sent (a retry sends the same bytes).
  static std::string request_digest(const v1::Scenario& sc) {
    std::string bytes;
    google::protobuf::io::StringOutputStream so(&bytes);
    google::protobuf::io::CodedOutputStream co(&so);
    co.SetSerializationDeterministic(true);
    sc.SerializeToCodedStream(&co);
    co.Trim();
    return jobs::sha256_hex(bytes);
  }

  // The answer to a request id used before: its job (the same request), or ALREADY_EXISTS.
  std::optional<Status> answer_retry(const std::string& owner, const v1::SubmitRequest& req, const std::string& request_hash,
                                     v1::Job* resp) {
    if (req.request_id().empty()) return std::nullopt;
    try {
      const auto prior = store->find_request(owner, req.request_id());
      if (!prior || prior->second.empty()) return std::nullopt;
      if (prior->second != request_hash)
        return Status(StatusCode::ALREADY_EXISTS, "request_id '" + req.request_id() + "' was used for job " + prior->first.job.id() +
                                                      " with another scenario; use a new request id for a new scenario");
      *resp = with_live(prior->first);
      return Status::OK;
    } catch (const std::exception& e) {
      return Status(StatusCode::INTERNAL, std::string("the job store failed: ") + e.what());
    }
  }

  Status SubmitScenario(grpc::ServerContext* ctx, const v1::SubmitRequest* req, v1::Job* resp) override {
    std::string owner;
    if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
    if (!req->has_scenario()) return {StatusCode::INVALID_ARGUMENT, "scenario: missing"};
    if (req->request_id().size() > 200) return {StatusCode::INVALID_ARGUMENT, "request_id: longer than 200 characters"};
    // A retry (the same request id) is answered before anything else, by the digest of the request.
    const std::string request_hash = request_digest(req->scenario());
    if (auto st = answer_retry(owner, *req, request_hash, resp)) return *st;
    v1::Scenario s = req->scenario();
    std::vector<std::string> uploads;  // of this submission: removed when it is refused
    InFlight in_flight{*this, {}};
    auto refuse = [&](Status st) {
      in_flight.release();
      if (!uploads.empty()) collect_uploads(uploads, owner);
      return st;
    };
    auto input = [&](const std::string& field, std::string* path) {
      const bool upload = path->rfind("upload:", 0) == 0;
      if (upload) in_flight.take(path->substr(7, 64));  // before it is looked at: not collected meanwhile
      Status st = resolve_input(cfg, field, path);
      if (st.ok() && upload) uploads.push_back(fs::path(*path).parent_path().filename().string());
      return st;
    };
    if (auto st = input("dem.path", s.mutable_dem()->mutable_path()); !st.ok()) return refuse(st);
    if (s.has_area_of_interest())
      if (auto st = input("area_of_interest.path", s.mutable_area_of_interest()->mutable_path()); !st.ok()) return refuse(st);
    for (int k = 0; k < s.releases_size(); ++k)
      if (auto st = input("releases[" + std::to_string(k) + "].path", s.mutable_releases(k)->mutable_path()); !st.ok())
        return refuse(st);
    // The job's limits: within the server's.
    {
      const auto& l = s.limits();
      if (!(std::isfinite(l.max_wall_s()) && l.max_wall_s() >= 0 && l.max_wall_s() <= cfg.max_job_wall_s()))
        return refuse({StatusCode::INVALID_ARGUMENT, "limits.max_wall_s: must lie in [0, " + jobs::json_number(cfg.max_job_wall_s()) +
                                                         "] s (0: the server's limit), got " + jobs::json_number(l.max_wall_s())});
      if (l.max_memory_bytes() < 0 || (cfg.max_job_memory_bytes() > 0 && l.max_memory_bytes() > cfg.max_job_memory_bytes()))
        return refuse({StatusCode::INVALID_ARGUMENT, "limits.max_memory_bytes: must lie in [0, " +
                                                         std::to_string(cfg.max_job_memory_bytes()) + "] (0: the server's limit), got " +
                                                         std::to_string(l.max_memory_bytes())});
    }
    const std::vector<std::string> roots(cfg.data_roots().begin(), cfg.data_roots().end());
    std::string hash;
    try {
      const auto r = jobs::resolve_scenario(s, "/");
      hash = jobs::scenario_hash(r);
    } catch (const jobs::ScenarioError& e) {
      return refuse({StatusCode::INVALID_ARGUMENT, jobs::client_message(e.what(), cfg.state_dir(), roots)});
    } catch (const terrain::TerrainError& e) {
      return refuse({StatusCode::INVALID_ARGUMENT, jobs::client_message(e.what(), cfg.state_dir(), roots)});
    } catch (const std::exception& e) {
      return refuse({StatusCode::INTERNAL, "validating the scenario failed: " + jobs::client_message(e.what(), cfg.state_dir(), roots)});
    }
    // Everything else `runout run` checks (unless these very inputs were accepted or computed before:
    // the hash covers the scenario and the content of every input).
    std::error_code ec;
    bool known = fs::exists(fs::path(sched->results_dir(hash)) / "run.json", ec);
    try {
      known = known || store->has_hash(hash);
    } catch (const std::exception&) {
    }
    if (!known) {
      if (!enter_validation())
        return refuse({StatusCode::RESOURCE_EXHAUSTED, "the server is checking too many submissions at once; try again"});
      const Status st = check_in_worker(cfg, s, [this](const std::string& l) { log(l); });
      leave_validation();
      if (!st.ok()) return refuse(st);
    }
    try {
      const auto out = store->submit(owner, hash, req->request_id(), s, cfg.max_queued_per_client(), request_hash);
      *resp = with_live(out.job);
      if (out.created) {
        try {
          sched->write_record(out.job);
        } catch (const std::exception& e) {
          log("job " + resp->id() + ": " + e.what() + " (`runout serve --recover` cannot rebuild it)");
        }
        log("job " + resp->id() + ": queued (" + owner + ", scenario " + hash.substr(0, 12) + ")");
        sched->touch(resp->id());
        sched->notify();
      }
    } catch (const jobs::RequestIdConflict& e) {
      return refuse({StatusCode::ALREADY_EXISTS, e.what()});
    } catch (const jobs::QueueFull& e) {
      return refuse({StatusCode::RESOURCE_EXHAUSTED, e.what()});
    } catch (const std::exception& e) {
      return {StatusCode::INTERNAL, jobs::client_message(e.what(), cfg.state_dir(), roots)};
    }
    return Status::OK;
  }

  Status GetJob(grpc::ServerContext* ctx, const v1::GetJobRequest* req, v1::Job* resp) override {
    std::string owner;
    if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
    const auto j = store->get(req->id(), owner);
    if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->id() + "'"};
    *resp = with_live(*j);
    return Status::OK;
  }

  Status ListJobs(grpc::ServerContext* ctx, const v1::ListJobsRequest* req, v1::ListJobsResponse* resp) override {
    std::string owner;
    if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
    int n = req->page_size() <= 0 ? 50 : std::min(req->page_size(), 500);
    std::vector<v1::JobState> states;
    for (int s : req->states()) states.push_back(v1::JobState(s));
    try {
      std::string next;
      for (const auto& j : store->list(owner, states, n, req->page_token(), &next)) *resp->add_jobs() = with_live(j);
      resp->set_next_page_token(next);
      resp->set_result_bytes_total(store->result_bytes_total(owner));
    } catch (const std::invalid_argument& e) {
      return {StatusCode::INVALID_ARGUMENT, e.what()};
    }
    return Status::OK;
  }

  Status CancelJob(grpc::ServerContext* ctx, const v1::CancelJobRequest* req, v1::Job* resp) override {
    std::string owner;
    if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
    auto j = store->cancel(req->id(), owner);
    if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->id() + "'"};
    if (j->job.state() == v1::RUNNING) {
      sched->cancel_running(req->id());
      log("job " + req->id() + ": cancel requested");
    } else if (j->job.state() == v1::CANCELLED && !j->job.transitions().empty() &&
               j->job.transitions(j->job.transitions_size() - 1).reason() == "cancelled by the client before it started") {
      std::ofstream lg(sched->log_path(req->id()), std::ios::app);  // `runout serve --recover` reads it
      lg << jobs::utc_now() << " cancelled: cancelled by the client before it started\n";
    }
    sched->touch(req->id());
    *resp = with_live(*j);
    return Status::OK;
  }

  Status WatchJob(grpc::ServerContext* ctx, const v1::WatchJobRequest* req, grpc::ServerWriter<v1::JobEvent>* w) override {
    std::string owner;
    if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
    std::uint64_t sent = ~std::uint64_t(0);
    auto last = std::chrono::steady_clock::now();
    for (;;) {
      const auto l = sched->live(req->id());
      const auto j = store->get(req->id(), owner);
      if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->id() + "'"};
      const auto now = std::chrono::steady_clock::now();
      if (l.version != sent || now - last > std::chrono::seconds(10) || jobs::is_final(j->job.state())) {
        v1::JobEvent ev;
        *ev.mutable_job() = with_live(*j);
        if (!w->Write(ev)) return {StatusCode::CANCELLED, "the client went away"};
        sent = l.version;
        last = now;
      }
      if (jobs::is_final(j->job.state())) return Status::OK;
      if (ctx->IsCancelled()) return {StatusCode::CANCELLED, "the client cancelled the watch"};
      {
        std::lock_guard lk(stop_mu);
        if (stopped) return {StatusCode::UNAVAILABLE, "the server is stopping"};
      }
      sched->wait_change(req->id(), l.version, std::chrono::milliseconds(500));
    }
  }

  // A job's log as its client sees it: the server's folders left out of the paths in it.
  std::string public_log(const std::string& id) {
    std::ifstream in(sched->log_path(id), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return jobs::client_message(ss.str(), cfg.state_dir(), {cfg.data_roots().begin(), cfg.data_roots().end()});
  }

  // The files of a job the client may download: the results of a succeeded job, and its log.
  std::vector<v1::ResultFile> result_files(const jobs::StoredJob& j) {
    std::vector<v1::ResultFile> out;
    std::error_code ec;
    if (j.job.state() == v1::SUCCEEDED && !j.results_removed) {
      const fs::path d = sched->results_dir(j.job.scenario_hash());
      for (const auto& e : fs::directory_iterator(d, ec)) {
        if (!e.is_regular_file(ec)) continue;
        v1::ResultFile f;
        f.set_name(e.path().filename().string());
        f.set_bytes(std::int64_t(e.file_size(ec)));
        out.push_back(f);
      }
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

  Status ListResults(grpc::ServerContext* ctx, const v1::ListResultsRequest* req, v1::ListResultsResponse* resp) override {
    std::string owner;
    if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
    const auto j = store->get(req->job_id(), owner);
    if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->job_id() + "'"};
    for (auto& f : result_files(*j)) *resp->add_files() = f;  // after retention: the log only
    return Status::OK;
  }

  Status DownloadResult(grpc::ServerContext* ctx, const v1::DownloadResultRequest* req, grpc::ServerWriter<v1::DataChunk>* w) override {
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
      offset += std::int64_t(n);
      first = false;
      if (last) break;
    }
    return Status::OK;
  }

  Status UploadInput(grpc::ServerContext* ctx, grpc::ServerReader<v1::UploadChunk>* r, v1::UploadResponse* resp) override {
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
    const std::int64_t held = store->upload_bytes(owner);
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
      if (held + bytes > cfg.max_upload_bytes_per_client())
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
    std::lock_guard ulk(upload_mu);  // not while the collector decides
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
};

Server::Server(const v1::ServerConfig& cfg) : impl_(std::make_unique<Impl>()) { impl_->cfg = resolve_config(cfg); }

Server::~Server() { shutdown(); }

void Server::start() {
  auto& m = *impl_;
  if (!m.cfg.log_file().empty()) {
    m.log_file.open(m.cfg.log_file(), std::ios::app);
    if (!m.log_file) throw ConfigError("log_file '" + m.cfg.log_file() + "': cannot open it");
  }
  m.tokens = std::make_unique<Tokens>(m.cfg.tokens_file(), [&m](const std::string& l) { m.log(l); });
  GDALAllRegister();  // once, before any call: registering from handler threads at once is not safe
  // One writer per state directory, for the server's life; then a store that does not forget (or,
  // asked to, one rebuilt under the same lock).
  try {
    m.lock = std::make_unique<jobs::StateLock>(m.cfg.state_dir());
    if (m.recover) {
      const auto rep = jobs::recover_store(m.cfg.state_dir(), *m.lock);
      m.recovery = rep.text();
      m.log(m.recovery);
    }
    jobs::check_store(m.cfg.state_dir());
  } catch (const jobs::StateError& e) {
    throw ConfigError(e.what());
  }
  fs::create_directories(fs::path(m.cfg.state_dir()) / "uploads");
  {
    std::error_code ec;  // checks of submissions cut off by a dead process
    fs::remove_all(fs::path(m.cfg.state_dir()) / "validate", ec);
  }
  const std::string db = (fs::path(m.cfg.state_dir()) / "jobs.db").string();
  try {
    m.store = std::make_unique<jobs::JobStore>(db);
  } catch (const std::exception& e) {
    throw ConfigError(std::string(e.what()) + " (" + db + ")");
  }
  jobs::SchedulerConfig sc;
  sc.state_dir = m.cfg.state_dir();
  sc.workers = m.cfg.workers();
  sc.threads_per_run = m.cfg.threads_per_run();
  sc.retention_days = m.cfg.retention_days();
  sc.retention_max_bytes = m.cfg.retention_max_bytes();
  sc.log = [&m](const std::string& s) { m.log(s); };
  sc.max_job_wall_s = m.cfg.max_job_wall_s();
  sc.max_job_memory_bytes = m.cfg.max_job_memory_bytes();
  sc.stop_grace_s = m.cfg.stop_grace_s();
  sc.max_crashes = m.cfg.max_crashes();
  sc.data_roots.assign(m.cfg.data_roots().begin(), m.cfg.data_roots().end());
  m.sched = std::make_unique<jobs::Scheduler>(*m.store, sc);
  {
    std::error_code ec;  // uploads cut off by a dead process
    for (const auto& e : fs::directory_iterator(fs::path(m.cfg.state_dir()) / "uploads", ec))
      if (e.path().filename().string().rfind(".tmp-", 0) == 0) fs::remove_all(e.path(), ec);
  }
  m.sched->start();  // before listening: requeue and cancel decisions are made before any call

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder b;
  std::shared_ptr<grpc::ServerCredentials> creds;
  if (!m.cfg.tls_cert().empty()) {
    grpc::SslServerCredentialsOptions o;
    o.pem_key_cert_pairs.push_back({read_text(m.cfg.tls_key()), read_text(m.cfg.tls_cert())});
    creds = grpc::SslServerCredentials(o);
  } else {
    creds = grpc::InsecureServerCredentials();
    if (!m.tokens->enabled() && m.cfg.listen().rfind("127.0.0.1:", 0) != 0 && m.cfg.listen().rfind("localhost:", 0) != 0)
      m.log("warning: listening on " + m.cfg.listen() + " without tokens_file: anyone who reaches the port can submit jobs");
  }
  b.AddListeningPort(m.cfg.listen(), creds, &m.bound_port);
  b.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);  // a port taken by another server is an error, not shared
  b.SetMaxReceiveMessageSize(m.cfg.max_message_bytes());
  b.SetMaxSendMessageSize(m.cfg.max_message_bytes());
  b.RegisterService(&m);
  m.server = b.BuildAndStart();
  if (!m.server || m.bound_port == 0)
    throw ConfigError("listen: cannot listen on " + m.cfg.listen() +
                      " (the port is in use, the address is not this machine's, or the TLS certificate and key do not match)");
  m.lock->set_listen(address());
  m.housekeeping = std::thread([&m] {
    const auto every = std::chrono::duration<double>(std::min(60.0, m.cfg.upload_ttl_s() / 4));
    std::unique_lock lk(m.stop_mu);
    while (!m.stopped) {
      m.housekeeping_cv.wait_for(lk, every, [&] { return m.stopped; });
      if (m.stopped) break;
      lk.unlock();
      try {
        m.collect_uploads();
      } catch (const std::exception& e) {
        m.log(std::string("upload collection failed: ") + e.what());
      }
      lk.lock();
    }
  });
  m.server->GetHealthCheckService()->SetServingStatus(true);
  std::ofstream sj(fs::path(m.cfg.state_dir()) / "server.json.tmp");
  sj << "{\"listen\": \"" << address() << "\", \"pid\": " << getpid() << ", \"started_utc\": \"" << jobs::utc_now() << "\"}\n";
  sj.close();
  fs::rename(fs::path(m.cfg.state_dir()) / "server.json.tmp", fs::path(m.cfg.state_dir()) / "server.json");
  m.log("runout server listening on " + address() + " (state " + m.cfg.state_dir() + ", " + std::to_string(m.cfg.workers()) +
        " worker(s), " + (m.tokens->enabled() ? "tokens" : "no authentication") + (m.cfg.tls_cert().empty() ? "" : ", TLS") + ")");
}

void Server::set_recover(bool on) { impl_->recover = on; }

const std::string& Server::recovery_report() const { return impl_->recovery; }

int Server::port() const { return impl_->bound_port; }

std::string Server::address() const {
  const std::string& l = impl_->cfg.listen();
  return l.substr(0, l.rfind(':')) + ":" + std::to_string(impl_->bound_port);
}

void Server::shutdown() {
  auto& m = *impl_;
  {
    std::lock_guard lk(m.stop_mu);
    if (m.stopped) return;
    m.stopped = true;
  }
  if (m.server) {
    m.server->GetHealthCheckService()->SetServingStatus(false);
    m.log("stopping: interrupting running jobs (they run again at the next start)");
    if (m.sched) m.sched->stop();
    m.server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(5));
    std::error_code ec;
    fs::remove(fs::path(m.cfg.state_dir()) / "server.json", ec);
    m.log("stopped");
  }
  m.stop_cv.notify_all();
  m.housekeeping_cv.notify_all();
  if (m.housekeeping.joinable()) m.housekeeping.join();
}

void Server::wait() {
  std::unique_lock lk(impl_->stop_mu);
  impl_->stop_cv.wait(lk, [&] { return impl_->stopped; });
}

}  // namespace runout::service
