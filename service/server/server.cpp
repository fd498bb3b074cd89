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

#include "service/server/impl.hpp"

namespace fs = std::filesystem;

namespace runout::service {

void Server::Impl::log(const std::string& line) {
  std::lock_guard lk(log_mu);
  std::ostream& o = log_file.is_open() ? static_cast<std::ostream&>(log_file) : std::cerr;
  o << jobs::utc_now() << " " << line << std::endl;
}

Status Server::Impl::authenticate(grpc::ServerContext* ctx, std::string* owner) {
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

v1::Job Server::Impl::with_live(const jobs::StoredJob& j) {
  v1::Job out = j.job;
  const auto l = sched->live(j.job.id());
  if (l.running && out.state() == v1::RUNNING) *out.mutable_progress() = l.progress;
  return out;
}

Server::Server(const v1::ServerConfig& cfg) : impl_(std::make_unique<Impl>()) { impl_->cfg = resolve_config(cfg); }

Server::~Server() { shutdown(); }

// The state directory: its lock, a rebuilt store when asked, the checks, the store.
void Server::Impl::open_state() {
  // One writer per state directory, for the server's life; then a store that does not forget (or,
  // asked to, one rebuilt under the same lock).
  try {
    lock = std::make_unique<jobs::StateLock>(cfg.state_dir());
    if (recover) {
      const auto rep = jobs::recover_store(cfg.state_dir(), *lock);
      recovery = rep.text();
      log(recovery);
    }
    jobs::check_store(cfg.state_dir());
  } catch (const jobs::StateError& e) {
    throw ConfigError(e.what());
  }
  fs::create_directories(fs::path(cfg.state_dir()) / "uploads");
  {
    std::error_code ec;  // checks of submissions cut off by a dead process
    fs::remove_all(fs::path(cfg.state_dir()) / "validate", ec);
  }
  const std::string db = (fs::path(cfg.state_dir()) / "jobs.db").string();
  try {
    store = std::make_unique<jobs::JobStore>(db);
  } catch (const std::exception& e) {
    throw ConfigError(std::string(e.what()) + " (" + db + ")");
  }
}

// The scheduler (it requeues and cancels before anything listens).
void Server::Impl::start_scheduler() {
  jobs::SchedulerConfig sc;
  sc.state_dir = cfg.state_dir();
  sc.workers = cfg.workers();
  sc.threads_per_run = cfg.threads_per_run();
  sc.retention_days = cfg.retention_days();
  sc.retention_max_bytes = cfg.retention_max_bytes();
  sc.log = [this](const std::string& s) { log(s); };
  sc.max_job_wall_s = cfg.max_job_wall_s();
  sc.max_job_memory_bytes = cfg.max_job_memory_bytes();
  sc.stop_grace_s = cfg.stop_grace_s();
  sc.max_crashes = cfg.max_crashes();
  sc.data_roots.assign(cfg.data_roots().begin(), cfg.data_roots().end());
  sc.mpi_launcher.assign(cfg.mpi_launcher().begin(), cfg.mpi_launcher().end());
  if (cfg.backend() == "slurm") {
    jobs::SlurmConfig slurm;
    slurm.partition = cfg.slurm_partition();
    slurm.sbatch_args.assign(cfg.slurm_sbatch_args().begin(), cfg.slurm_sbatch_args().end());
    slurm.worker_exe = cfg.slurm_worker();
    slurm.mpi = cfg.slurm_mpi();
    sc.slurm = slurm;
    sc.max_job_memory_bytes = 0;  // Slurm enforces memory (sbatch --mem); the server cannot see the nodes
  }
  sched = std::make_unique<jobs::Scheduler>(*store, sc);
  {
    std::error_code ec;  // uploads cut off by a dead process
    for (const auto& e : fs::directory_iterator(fs::path(cfg.state_dir()) / "uploads", ec))
      if (e.path().filename().string().rfind(".tmp-", 0) == 0) fs::remove_all(e.path(), ec);
  }
  sched->start();  // before listening: requeue and cancel decisions are made before any call
}

// The gRPC server on cfg.listen (TLS when configured).
void Server::Impl::listen() {
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder b;
  std::shared_ptr<grpc::ServerCredentials> creds;
  if (!cfg.tls_cert().empty()) {
    grpc::SslServerCredentialsOptions o;
    o.pem_key_cert_pairs.push_back({read_text(cfg.tls_key()), read_text(cfg.tls_cert())});
    creds = grpc::SslServerCredentials(o);
  } else {
    creds = grpc::InsecureServerCredentials();
    if (!tokens->enabled() && cfg.listen().rfind("127.0.0.1:", 0) != 0 && cfg.listen().rfind("localhost:", 0) != 0)
      log("warning: listening on " + cfg.listen() + " without tokens_file: anyone who reaches the port can submit jobs");
  }
  b.AddListeningPort(cfg.listen(), creds, &bound_port);
  b.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);  // a port taken by another server is an error, not shared
  b.SetMaxReceiveMessageSize(cfg.max_message_bytes());
  b.SetMaxSendMessageSize(cfg.max_message_bytes());
  b.RegisterService(this);
  server = b.BuildAndStart();
  if (!server || bound_port == 0)
    throw ConfigError("listen: cannot listen on " + cfg.listen() +
                      " (the port is in use, the address is not this machine's, or the TLS certificate and key do not match)");
}

// Collects unused uploads every quarter of their time to live (at most every minute).
void Server::Impl::start_housekeeping() {
  housekeeping = std::thread([this] {
    const auto every = std::chrono::duration<double>(std::min(60.0, cfg.upload_ttl_s() / 4));
    std::unique_lock lk(stop_mu);
    while (!stopped) {
      housekeeping_cv.wait_for(lk, every, [&] { return stopped; });
      if (stopped) break;
      lk.unlock();
      try {
        collect_uploads();
      } catch (const std::exception& e) {
        log(std::string("upload collection failed: ") + e.what());
      }
      lk.lock();
    }
  });
}

void Server::start() {
  auto& m = *impl_;
  if (!m.cfg.log_file().empty()) {
    m.log_file.open(m.cfg.log_file(), std::ios::app);
    if (!m.log_file) throw ConfigError("log_file '" + m.cfg.log_file() + "': cannot open it");
  }
  m.tokens = std::make_unique<Tokens>(m.cfg.tokens_file(), [&m](const std::string& l) { m.log(l); });
  GDALAllRegister();  // once, before any call: registering from handler threads at once is not safe
  m.open_state();
  m.start_scheduler();
  m.listen();
  m.lock->set_listen(address());
  m.start_housekeeping();
  m.server->GetHealthCheckService()->SetServingStatus(true);
  v1::ServerInfo info;
  info.set_listen(address());
  info.set_pid(getpid());
  info.set_started_utc(jobs::utc_now());
  jobs::write_server_info(m.cfg.state_dir(), info);
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
  m.stopping = true;  // checks of submissions end (UNAVAILABLE): gRPC's shutdown waits for their handlers
  m.validate_cv.notify_all();
  if (m.server) {
    m.server->GetHealthCheckService()->SetServingStatus(false);
    m.log("stopping: interrupting running jobs (they run again at the next start)");
    if (m.sched) m.sched->stop();
    // Calls still in flight after half a second are cancelled: a fetch whose client stopped reading
    // would otherwise hold the stop until the deadline (clients retry; nothing of theirs is lost).
    m.server->Shutdown(std::chrono::system_clock::now() + std::chrono::milliseconds(500));
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

