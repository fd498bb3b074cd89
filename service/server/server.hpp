#pragma once
// The gRPC batch server: the runout.v1.Runout service over the job store and workers of jobs/,
// standard health checking and server reflection, bearer-token authentication and optional TLS.
#include <memory>
#include <stdexcept>
#include <string>

#include "runout/v1/service.pb.h"

namespace runout::service {

struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Fill the defaults of a server configuration and check it (throws ConfigError naming the key).
v1::ServerConfig resolve_config(v1::ServerConfig c);
/// Read a JSON server configuration file (throws ConfigError).
v1::ServerConfig read_config_file(const std::string& path);

class Server {
 public:
  explicit Server(const v1::ServerConfig& cfg);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Open the store, queue again what a previous process left running, start the workers, listen.
  /// Writes <state_dir>/server.json with the address and pid. Throws ConfigError on failure.
  void start();
  /// Before start(): rebuild a missing, empty or damaged job store (jobs::recover_store) under the
  /// state directory's lock, then start as usual.
  void set_recover(bool on);
  /// What the rebuilding did ("" when not asked).
  const std::string& recovery_report() const;
  /// The port actually bound (when the configuration asked for port 0).
  int port() const;
  std::string address() const;
  /// Stop accepting calls, interrupt running jobs (queued again), wait for the workers.
  void shutdown();
  /// Block until shutdown() is called from another thread.
  void wait();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace runout::service
