#pragma once
// The gRPC service behind runout::service::Server: its state and its handlers. Internal to
// service/server/: server.cpp (start, stop, authentication, log), submit.cpp (SubmitScenario and
// the checks at the door), job_queries.cpp (GetJob, ListJobs, CancelJob, WatchJob), files.cpp
// (uploads and results).
#include <grpcpp/grpcpp.h>

#include <atomic>
#include <condition_variable>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "jobs/system/scheduler.hpp"
#include "jobs/system/state_dir.hpp"
#include "jobs/system/store.hpp"
#include "runout/v1/service.grpc.pb.h"
#include "service/server/server.hpp"
#include "service/server/tokens.hpp"

namespace runout::service {

using grpc::Status;
using grpc::StatusCode;

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
  std::map<std::string, std::int64_t> bytes_arriving;  // per client, of its uploads in progress; guarded by upload_mu
  std::mutex validate_mu;
  std::condition_variable validate_cv;
  int validating = 0;
  std::ofstream log_file;
  std::mutex stop_mu;
  std::condition_variable stop_cv;
  bool stopped = false;
  std::atomic<bool> stopping{false};  // set first by shutdown(): submissions being checked end






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















    void log(const std::string& line);

    Status authenticate(grpc::ServerContext* ctx, std::string* owner);

    v1::Job with_live(const jobs::StoredJob& j);

    // The uploads a scenario names (their ids), from its resolved paths.
    std::vector<std::string> uploads_of(const v1::Scenario& s) const;

    // Remove uploads that nothing uses: no queued or running job, no submission in progress. `owner`
    // given: the uploads of that client's refused submission (its record of them is dropped, and a
    // folder goes only when no client holds a record of it); else all whose last use is older than
    // the upload time-to-live.
    void collect_uploads(const std::vector<std::string>& only = {}, const std::string& owner = "");

    // At most this many checks of submissions at once (each a process that may use a job's memory).
    bool enter_validation();

    void leave_validation();

    // The digest of a submitted scenario as sent (a retry sends the same bytes).
    static std::string request_digest(const v1::Scenario& sc);

    // The answer to a request id used before: its job (the same request), or ALREADY_EXISTS.
    std::optional<Status> answer_retry(const std::string& owner, const v1::SubmitRequest& req, const std::string& request_hash,
                                       v1::Job* resp);

    // A submission's inputs resolved on this server (its uploads taken as in flight first).
    Status resolve_inputs(v1::Scenario& s, InFlight& in_flight);

    Status SubmitScenario(grpc::ServerContext* ctx, const v1::SubmitRequest* req, v1::Job* resp) override;

    Status GetJob(grpc::ServerContext* ctx, const v1::GetJobRequest* req, v1::Job* resp) override;

    Status ListJobs(grpc::ServerContext* ctx, const v1::ListJobsRequest* req, v1::ListJobsResponse* resp) override;

    Status CancelJob(grpc::ServerContext* ctx, const v1::CancelJobRequest* req, v1::Job* resp) override;

    Status WatchJob(grpc::ServerContext* ctx, const v1::WatchJobRequest* req, grpc::ServerWriter<v1::JobEvent>* w) override;

    // A job's log as its client sees it: the server's folders left out of the paths in it.
    std::string public_log(const std::string& id);

    // The files of a job the client may download: the results of a succeeded job, and its log.
    std::vector<v1::ResultFile> result_files(const jobs::StoredJob& j);

    Status ListResults(grpc::ServerContext* ctx, const v1::ListResultsRequest* req, v1::ListResultsResponse* resp) override;

    Status DownloadResult(grpc::ServerContext* ctx, const v1::DownloadResultRequest* req, grpc::ServerWriter<v1::DataChunk>* w) override;

    Status UploadInput(grpc::ServerContext* ctx, grpc::ServerReader<v1::UploadChunk>* r, v1::UploadResponse* resp) override;

  // Server::start in steps (server.cpp).
  void open_state();
  void start_scheduler();
  void listen();
  void start_housekeeping();
};

}  // namespace runout::service
