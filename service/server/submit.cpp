// Submissions: the checks at the door (limits, inputs, validation in a worker), retries answered by
// their request, queueing.
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

#include "jobs/ensemble/variations.hpp"
#include "jobs/scenario/scenario.hpp"
#include "jobs/scenario/text_limits.hpp"
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

// At most this many checks of submissions at once (each a process that may use a job's memory).
bool Server::Impl::enter_validation() {
  std::unique_lock lk(validate_mu);
  const int limit = std::max(2, cfg.workers());
  if (!validate_cv.wait_for(lk, std::chrono::seconds(60), [&] { return validating < limit || stopping; }) || stopping) return false;
  ++validating;
  return true;
}

void Server::Impl::leave_validation() {
  {
    std::lock_guard lk(validate_mu);
    --validating;
  }
  validate_cv.notify_one();
}

// The digest of a submitted scenario as sent (a retry sends the same bytes).
std::string Server::Impl::request_digest(const v1::Scenario& sc) {
  std::string bytes;
  google::protobuf::io::StringOutputStream so(&bytes);
  google::protobuf::io::CodedOutputStream co(&so);
  co.SetSerializationDeterministic(true);
  sc.SerializeToCodedStream(&co);
  co.Trim();
  return jobs::sha256_hex(bytes);
}

// The answer to a request id used before: its job (the same request), or ALREADY_EXISTS.
std::optional<Status> Server::Impl::answer_retry(const std::string& owner, const v1::SubmitRequest& req, const std::string& request_hash,
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

namespace {

// Text first: nothing after it reads an unbounded name or a path cut short by a NUL byte.
Status check_text(const v1::SubmitRequest& req) {
  if (!req.has_scenario()) return {StatusCode::INVALID_ARGUMENT, "scenario: missing"};
  if (const auto p = jobs::text_problem(req.request_id(), jobs::kMaxRequestIdBytes); !p.empty())
    return {StatusCode::INVALID_ARGUMENT, "request_id: " + p};
  try {
    jobs::check_text_limits(req.scenario());
  } catch (const jobs::ScenarioError& e) {
    return {StatusCode::INVALID_ARGUMENT, e.what()};
  }
  return Status::OK;
}

// The job's limits, and its ranks: within the server's.
Status check_limits(const v1::ServerConfig& cfg, const v1::Scenario& s) {
  if (s.ranks() < 0 || s.ranks() > cfg.max_ranks_per_job())
    return {StatusCode::INVALID_ARGUMENT, "ranks: must lie in 1.." + std::to_string(cfg.max_ranks_per_job()) +
                                              " on this server (max_ranks_per_job; 0: one process), got " + std::to_string(s.ranks())};
  const v1::JobLimits& l = s.limits();
  if (!(std::isfinite(l.max_wall_s()) && l.max_wall_s() >= 0 && l.max_wall_s() <= cfg.max_job_wall_s()))
    return {StatusCode::INVALID_ARGUMENT, "limits.max_wall_s: must lie in [0, " + jobs::json_number(cfg.max_job_wall_s()) +
                                              "] s (0: the server's limit), got " + jobs::json_number(l.max_wall_s())};
  if (l.max_memory_bytes() < 0 || (cfg.max_job_memory_bytes() > 0 && l.max_memory_bytes() > cfg.max_job_memory_bytes()))
    return {StatusCode::INVALID_ARGUMENT, "limits.max_memory_bytes: must lie in [0, " + std::to_string(cfg.max_job_memory_bytes()) +
                                              "] (0: the server's limit), got " + std::to_string(l.max_memory_bytes())};
  return Status::OK;
}

}  // namespace

// A submission's inputs resolved on this server (the first refusal returned); each upload is taken
// as in flight before it is looked at, so that it is not collected meanwhile.
Status Server::Impl::resolve_inputs(v1::Scenario& s, InFlight& in_flight) {
  Status bad_input = Status::OK;
  jobs::for_each_input_path(s, [&](const std::string& field, std::string* path) {
    if (!bad_input.ok()) return;
    if (path->rfind("upload:", 0) == 0) in_flight.take(path->substr(7, 64));
    bad_input = resolve_input(cfg, field, path);
  });
  return bad_input;
}

Status Server::Impl::SubmitScenario(grpc::ServerContext* ctx, const v1::SubmitRequest* req, v1::Job* resp) {
  std::string owner;
  if (auto st = authenticate(ctx, &owner); !st.ok()) return st;
  v1::Scenario s = req->scenario();
  // Every upload the submission names is removed when it is refused, whatever the reason.
  std::vector<std::string> uploads;
  jobs::for_each_input_path(s, [&](const std::string&, std::string* path) {
    if (path->rfind("upload:", 0) == 0 && is_hex64(path->substr(7, 64))) uploads.push_back(path->substr(7, 64));
  });
  InFlight in_flight{*this, {}};
  auto refuse = [&](Status st) {
    in_flight.release();
    if (!uploads.empty()) collect_uploads(uploads, owner);
    return st;
  };
  if (auto st = check_text(*req); !st.ok()) return refuse(st);
  // A retry (the same request id) is answered before anything else, by the digest of the request.
  const std::string request_hash = request_digest(req->scenario());
  if (auto st = answer_retry(owner, *req, request_hash, resp)) return st->ok() ? *st : refuse(*st);
  if (auto st = full_disk(cfg); !st.ok()) return refuse(st);
  if (auto st = resolve_inputs(s, in_flight); !st.ok()) return refuse(st);
  if (auto st = check_limits(cfg, s); !st.ok()) return refuse(st);
  const std::vector<std::string> roots(cfg.data_roots().begin(), cfg.data_roots().end());
  std::string hash;
  std::optional<jobs::ensemble::Plan> plan;  // an ensemble: its members
  try {
    const auto r = jobs::resolve_scenario(s, "/");
    if (jobs::ensemble::is_ensemble(r.scenario)) {
      plan = jobs::ensemble::plan(r);
      hash = plan->hash;
    } else {
      hash = jobs::scenario_hash(r);
    }
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
      return refuse(stopping ? Status(StatusCode::UNAVAILABLE, "the server is stopping; submit again when it is back")
                             : Status(StatusCode::RESOURCE_EXHAUSTED, "the server is checking too many submissions at once; try again"));
    // An ensemble: its first member stands for the others' inputs (they differ in numbers only).
    const Status st = check_in_worker(cfg, plan ? plan->members.front().member.scenario : s, [this](const std::string& l) { log(l); },
                                      [this] { return stopping.load(); });
    leave_validation();
    if (!st.ok()) {  // a check that could not write for a full disk says so, not that the scenario is bad
      if (auto fd = full_disk(cfg, "checking the scenario failed (" + st.error_message() + ")"); !fd.ok()) return refuse(fd);
      return refuse(st);
    }
  }
  try {
    std::vector<jobs::JobStore::NewMember> members;
    if (plan)
      for (const auto& m : plan->members) members.push_back({m.member.index, m.hash, m.member.scenario});
    // A request id answered by an earlier identical job: that job's log keeps it, written before the
    // store commits (`runout serve --recover` reads the line).
    auto record_request = [&](const jobs::StoredJob& j) {
      if (!sched->append_job_log(j.job.id(), jobs::request_log_line(req->request_id(), request_hash)))
        throw std::runtime_error("cannot write the log of job " + j.job.id());
    };
    const auto out =
        store->submit_ensemble(owner, hash, req->request_id(), s, members, cfg.max_queued_per_client(), request_hash, record_request);
    *resp = with_live(out.job);
    if (out.created) {
      try {
        sched->write_record(out.job);
        for (const auto& m : plan ? store->members(out.job.job.id()) : std::vector<jobs::StoredJob>{}) sched->write_record(m);
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
    const std::string m = jobs::client_message(e.what(), cfg.state_dir(), roots);
    if (auto st = full_disk(cfg, "the job store cannot be written (" + m + ")"); !st.ok()) return refuse(st);
    return refuse({StatusCode::INTERNAL, m});
  }
  return Status::OK;
}

}  // namespace runout::service
