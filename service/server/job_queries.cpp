// Job queries: one job, a page of jobs, cancelling, and following a job to its end.
#include "service/server/impl.hpp"

#include <algorithm>

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

Status Server::Impl::GetJob(grpc::ServerContext* ctx, const v1::GetJobRequest* req, v1::Job* resp) {
  std::string owner;
  if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
  const auto j = store->get(req->id(), owner);
  if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->id() + "'"};
  *resp = with_live(*j);
  return Status::OK;
}

Status Server::Impl::ListJobs(grpc::ServerContext* ctx, const v1::ListJobsRequest* req, v1::ListJobsResponse* resp) {
  std::string owner;
  if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
  int n = req->page_size() <= 0 ? 50 : std::min(req->page_size(), 500);
  std::vector<v1::JobState> states;
  for (int s : req->states()) states.push_back(v1::JobState(s));
  try {
    std::string next;
    if (!req->parent_id().empty()) {  // an ensemble's members, a page from the index in page_token on
      if (!store->get(req->parent_id(), owner)) return {StatusCode::NOT_FOUND, "no job '" + req->parent_id() + "'"};
      std::size_t from = 0;
      try {
        from = req->page_token().empty() ? 0 : std::stoul(req->page_token());
      } catch (...) {
        return {StatusCode::INVALID_ARGUMENT, "page_token: not a token this server gave out"};
      }
      const auto members = store->members(req->parent_id());
      for (std::size_t k = from; k < members.size() && k < from + std::size_t(n); ++k)
        if (states.empty() || std::find(states.begin(), states.end(), members[k].job.state()) != states.end())
          *resp->add_jobs() = with_live(members[k]);
      if (from + std::size_t(n) < members.size()) resp->set_next_page_token(std::to_string(from + std::size_t(n)));
      return Status::OK;
    }
    for (const auto& j : store->list(owner, states, n, req->page_token(), &next)) *resp->add_jobs() = with_live(j);
    resp->set_next_page_token(next);
    resp->set_result_bytes_total(store->result_bytes_total(owner));
  } catch (const std::invalid_argument& e) {
    return {StatusCode::INVALID_ARGUMENT, e.what()};
  }
  return Status::OK;
}

Status Server::Impl::CancelJob(grpc::ServerContext* ctx, const v1::CancelJobRequest* req, v1::Job* resp) {
  std::string owner;
  if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
  std::vector<jobs::JobStore::Change> ended;
  // Each log keeps its job's history (`runout serve --recover` reads it): the line is written before
  // the store commits, so that no reader (a client, or a recovery after a crash) sees a cancelled
  // job whose log does not say so; a commit that fails says so in the log after it.
  auto write_lines = [&](const std::vector<jobs::JobStore::Change>& changes, const std::string& word, const std::string& why) {
    for (const auto& e : changes) sched->append_job_log(e.id, word + ": " + (why.empty() ? e.reason : why));
  };
  std::optional<jobs::StoredJob> j;
  try {
    j = store->cancel(req->id(), owner, &ended, [&](const auto& changes) { write_lines(changes, "cancelled", ""); });
  } catch (const std::exception& e) {
    write_lines(ended, "queued", std::string("the cancel could not be recorded (") + e.what() + ")");
    return {StatusCode::INTERNAL, std::string("the job store failed: ") + e.what()};
  }
  if (!j) return {StatusCode::NOT_FOUND, "no job '" + req->id() + "'"};
  if (j->job.state() == v1::RUNNING) {
    sched->cancel_running(req->id());
    log("job " + req->id() + ": cancel requested");
  }
  sched->touch(req->id());
  *resp = with_live(*j);
  return Status::OK;
}

Status Server::Impl::WatchJob(grpc::ServerContext* ctx, const v1::WatchJobRequest* req, grpc::ServerWriter<v1::JobEvent>* w) {
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
std::string Server::Impl::public_log(const std::string& id) {
  std::ifstream in(sched->log_path(id), std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return jobs::client_message(ss.str(), cfg.state_dir(), {cfg.data_roots().begin(), cfg.data_roots().end()});
}

}  // namespace runout::service
