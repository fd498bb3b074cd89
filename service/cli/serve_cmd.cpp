// runout serve: the gRPC batch server in the foreground until SIGINT or SIGTERM.
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <pthread.h>
#include <unistd.h>
#include <signal.h>

#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "jobs/system/state_dir.hpp"
#include "service/cli/commands.hpp"
#include "service/server/server.hpp"

namespace runout::cli {

namespace {

// Everything of the server's is done and durable when its shutdown returns: jobs interrupted with
// their checkpoints, every store change committed (synced), the log flushed, server.json removed.
// gRPC's own teardown would still wait for the handler threads of calls whose clients stopped
// reading (a fetch that stalls: 10 s measured), holding the state directory's lock meanwhile; the
// process ends now instead, and the operating system drops the lock.
[[noreturn]] void exit_stopped() {
  std::cout.flush();
  std::cerr.flush();
  std::_Exit(kOk);
}

}  // namespace

int serve(const std::vector<std::string>& args) {
  v1::ServerConfig file_cfg, cli_cfg;
  std::vector<std::string> roots;
  bool recover = false;
  std::string config, listen, state_dir, tokens, tls_cert, tls_key, log_file, workers, threads_per_run, backend;
  CLI::App app{"Run the gRPC batch server (runout.v1.Runout, health checking, reflection) until SIGINT or SIGTERM.\n"
               "Options override the JSON configuration file (deploy/README.md lists every key). Each job runs in a\n"
               "worker process of its own; jobs left running by a killed server are queued again at the next start.\n"
               "One server per state directory (a second one exits).",
               "runout serve"};
  prepare(app);
  app.add_flag("--recover", recover,
               "Rebuild a missing, empty or damaged job store from the job records, logs and results, then start "
               "(docs/user/operations.md)");
  app.add_option("--config", config, "JSON configuration file (runout.v1.ServerConfig)")->type_name("FILE");
  app.add_option("--listen", listen, "Address to listen on (default 127.0.0.1:50051; port 0: any free port)")->type_name("HOST:PORT");
  app.add_option("--state-dir", state_dir, "The job store, uploads, logs and results (default ./runout-state)")->type_name("DIR");
  app.add_option("--data-root", roots, "A folder whose files scenarios may name by path (repeat for more; replaces the file's list)")
      ->type_name("DIR")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_option("--tokens", tokens, "The clients' bearer tokens, one per line, plain or sha256:HEX (none: no authentication)")->type_name("FILE");
  app.add_option("--tls-cert", tls_cert, "PEM certificate: serve TLS (with --tls-key)")->type_name("FILE");
  app.add_option("--tls-key", tls_key, "PEM private key of --tls-cert")->type_name("FILE");
  app.add_option("--workers", workers, "Jobs run at a time, a positive integer (default 1)")->type_name("N");
  app.add_option("--threads-per-run", threads_per_run, "OpenMP threads of each job, a positive integer (default: cores / workers)")->type_name("N");
  app.add_option("--log-file", log_file, "The server's log (default: standard error)")->type_name("FILE");
  app.add_option("--backend", backend,
                 "Where jobs run: local (worker processes on this machine, default) or slurm (tasks of Slurm job arrays; the "
                 "state directory on a filesystem the compute nodes share; --workers: tasks on the cluster at once)")
      ->type_name("NAME");
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  auto number = [&](const char* flag, const std::string& v, int* out) {
    const auto n = positive_int(v);
    if (!n) usage_error("runout serve", std::string(flag) + " takes a positive integer, got '" + v + "'");
    *out = n.value_or(0);
    return n.has_value();
  };
  int n = 0;
  if (app.count("--workers")) {
    if (!number("--workers", workers, &n)) return kUsage;
    cli_cfg.set_workers(n);
  }
  if (app.count("--threads-per-run")) {
    if (!number("--threads-per-run", threads_per_run, &n)) return kUsage;
    cli_cfg.set_threads_per_run(n);
  }
  if (app.count("--listen")) cli_cfg.set_listen(listen);
  if (app.count("--state-dir")) cli_cfg.set_state_dir(state_dir);
  if (app.count("--tokens")) cli_cfg.set_tokens_file(tokens);
  if (app.count("--tls-cert")) cli_cfg.set_tls_cert(tls_cert);
  if (app.count("--tls-key")) cli_cfg.set_tls_key(tls_key);
  if (app.count("--log-file")) cli_cfg.set_log_file(log_file);
  if (app.count("--backend")) cli_cfg.set_backend(backend);
  if (app.count("--config")) {
    try {
      file_cfg = service::read_config_file(config);
    } catch (const std::exception& e) {
      std::cerr << "runout serve: " << e.what() << "\n";
      return kBadInput;
    }
  }
  const bool have_roots = app.count("--data-root") > 0;
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
    exit_stopped();
  } catch (const service::ConfigError& e) {
    std::cerr << "runout serve: " << e.what() << "\n";
    return kBadInput;
  }
  return kOk;
}

}  // namespace runout::cli
