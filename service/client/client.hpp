#pragma once
// A client of the runout.v1.Runout service, used by the command line (submit, status, watch,
// cancel, fetch, health), the nightly regression and the load benchmark.
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "runout/v1/service.pb.h"

namespace runout::service {

/// A failed call: the gRPC status code (as an int, grpc::StatusCode) and the server's message.
struct RpcError : std::runtime_error {
  RpcError(int code, const std::string& what) : std::runtime_error(what), code(code) {}
  int code;
};

struct ClientOptions {
  std::string server = "127.0.0.1:50051";
  std::string token;    ///< bearer token; empty: none sent
  std::string tls_ca;   ///< PEM file of the CA that signed the server's certificate: TLS
  bool tls = false;     ///< TLS with the system's roots
  double timeout_s = 60;  ///< deadline of unary calls
  double watch_timeout_s = 0;  ///< deadline of a whole watch; 0: none
};

class Client {
 public:
  explicit Client(const ClientOptions& o);
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// Upload one input: the files in order (the first is the one a scenario names, the rest its
  /// companions). Returns the upload reference ("upload:ID/NAME").
  v1::UploadResponse upload(const std::vector<std::string>& files);
  v1::Job submit(const v1::Scenario& s, const std::string& request_id = "");
  v1::Job get(const std::string& id);
  v1::ListJobsResponse list(const std::vector<v1::JobState>& states = {}, int page_size = 50, const std::string& page_token = "");
  v1::Job cancel(const std::string& id);
  /// An ensemble's members, in order (every page).
  std::vector<v1::Job> members(const std::string& parent_id);
  /// Follow a job until it ends; `on_event` sees every event. Returns the final job.
  v1::Job watch(const std::string& id, const std::function<void(const v1::Job&)>& on_event = {});
  v1::ListResultsResponse results(const std::string& id);
  /// Download one result to `dest` (written beside it first, checked against the server's SHA-256).
  void download(const std::string& id, const std::string& name, const std::string& dest);
  /// grpc.health.v1 Check of the whole server: true when SERVING.
  bool healthy();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Replace every input path of a scenario (relative to `base_dir`) by an upload of the file and its
/// companions (a shapefile's .shx, .dbf, .prj, .cpg; a raster's .prj, .aux.xml, .hdr, .tfw).
v1::Scenario upload_inputs(Client& c, v1::Scenario s, const std::string& base_dir);

/// "queued", "running", ...
std::string state_word(v1::JobState s);

/// Whether a result's name from the server is safe to write under an output folder: a plain file
/// name, or one folder and a plain file name ("nest/run.json"); no part empty or starting with a
/// dot, no backslash.
bool result_name_ok(const std::string& name);

}  // namespace runout::service
