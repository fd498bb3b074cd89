// runout serve: the gRPC batch server in the foreground until SIGINT or SIGTERM.
#include <fcntl.h>
#include <pthread.h>
#include <unistd.h>
#include <signal.h>

#include <iostream>
#include <string>
#include <vector>

#include "jobs/state_dir.hpp"
#include "service/cli/commands.hpp"
#include "service/server/server.hpp"

namespace runout::cli {

int serve(const std::vector<std::string>& args) {
  v1::ServerConfig file_cfg, cli_cfg;
  std::vector<std::string> roots;
  bool have_roots = false, recover = false;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const auto& a = args[k];
    const bool has_value = k + 1 < args.size();
    auto value = [&]() -> std::string { return args[++k]; };
    auto number = [&](const std::string& v, int* out) {
      try {
        std::size_t used = 0;
        *out = std::stoi(v, &used);
        return used == v.size();
      } catch (...) {
        return false;
      }
    };
    if (a == "--recover") {
      recover = true;
      continue;
    }
    if (a == "--config" || a == "--listen" || a == "--state-dir" || a == "--data-root" || a == "--tokens" ||
        a == "--tls-cert" || a == "--tls-key" || a == "--workers" || a == "--threads-per-run" || a == "--log-file") {
      if (!has_value) {
        std::cerr << "runout serve: " << a << " needs a value\n";
        return kUsage;
      }
      const std::string v = value();
      int n = 0;
      if (a == "--config") {
        try {
          file_cfg = service::read_config_file(v);
        } catch (const std::exception& e) {
          std::cerr << "runout serve: " << e.what() << "\n";
          return kBadInput;
        }
      } else if (a == "--listen") {
        cli_cfg.set_listen(v);
      } else if (a == "--state-dir") {
        cli_cfg.set_state_dir(v);
      } else if (a == "--data-root") {
        roots.push_back(v);
        have_roots = true;
      } else if (a == "--tokens") {
        cli_cfg.set_tokens_file(v);
      } else if (a == "--tls-cert") {
        cli_cfg.set_tls_cert(v);
      } else if (a == "--tls-key") {
        cli_cfg.set_tls_key(v);
      } else if (a == "--log-file") {
        cli_cfg.set_log_file(v);
      } else if (!number(v, &n) || n < 1) {
        std::cerr << "runout serve: " << a << " takes a positive integer, got '" << v << "'\n";
        return kUsage;
      } else if (a == "--workers") {
        cli_cfg.set_workers(n);
      } else {
        cli_cfg.set_threads_per_run(n);
      }
    } else {
      std::cerr << "runout serve: unknown option '" << a << "' (see runout help)\n";
      return kUsage;
    }
  }
  // Command-line options override the file.
  v1::ServerConfig cfg = file_cfg;
  cfg.MergeFrom(cli_cfg);
  if (have_roots) {
    cfg.clear_data_roots();
    for (const auto& r : roots) cfg.add_data_roots(r);
  }

  // Standard input, output and error open (a closed one would be reused by a pipe to a worker).
  for (int fd = 0; fd <= 2; ++fd)
    if (fcntl(fd, F_GETFD) < 0) open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);
  // A file-size limit makes writes fail (and say so), not the server die.
  signal(SIGXFSZ, SIG_IGN);
  signal(SIGPIPE, SIG_IGN);
  // Signals are taken by this thread only (sigwait below): block them before any thread starts.
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  try {
    service::Server server(cfg);
    server.set_recover(recover);
    server.start();
    if (recover) std::cerr << "runout serve: " << server.recovery_report() << std::endl;
    std::cout << "runout server listening on " << server.address() << std::endl;
    int sig = 0;
    sigwait(&set, &sig);
    std::cerr << "runout serve: " << (sig == SIGINT ? "SIGINT" : "SIGTERM") << ", stopping\n";
    server.shutdown();
  } catch (const service::ConfigError& e) {
    std::cerr << "runout serve: " << e.what() << "\n";
    return kBadInput;
  }
  return kOk;
}

}  // namespace runout::cli
