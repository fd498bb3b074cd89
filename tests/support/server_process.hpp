#pragma once
// Test support: a real `runout serve` process on 127.0.0.1 with an ephemeral port and a state
// directory of the test's, started and stopped by its pid; temporary folders; client options.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "jobs/system/state_dir.hpp"
#include "service/client/client.hpp"
#include "tests/support/temp_dir.hpp"

namespace runout::test_support {

namespace fs = std::filesystem;

/// The program under test: RUNOUT_BIN, or the one $RUNOUT_TEST_BINARY names (to run the
/// fault-injection suite against another build, e.g. an older one).
inline std::string runout_binary() {
  const char* e = std::getenv("RUNOUT_TEST_BINARY");
  return e && *e ? std::string(e) : std::string(RUNOUT_BIN);
}

struct ServerOptions {
  std::int64_t file_size_limit = 0;  ///< RLIMIT_FSIZE of the server (and its workers); 0: none
  bool expect_listening = true;      ///< false: the server is expected to refuse to start
  std::string listen = "127.0.0.1:0";
  std::string binary = runout_binary();  ///< the program to start
};

// `runout serve` as a child process; its standard error goes to STATE/../server.err.
class ServerProcess {
 public:
  ServerProcess(const fs::path& state, std::vector<std::string> extra, ServerOptions o = {})
      : state_(state), extra_(std::move(extra)), opt_(o) {
    start();
  }
  ~ServerProcess() { stop(SIGTERM); }
  void start() {
    fs::create_directories(state_.parent_path());
    fs::remove(state_ / "server.json");
    std::vector<std::string> args = {opt_.binary, "serve", "--listen", opt_.listen, "--state-dir", state_.string(),
                                     "--log-file", (state_.parent_path() / "server.log").string()};
    args.insert(args.end(), extra_.begin(), extra_.end());
    const std::string err = (state_.parent_path() / "server.err").string();
    const std::int64_t fsize = opt_.file_size_limit;
    pid_ = fork();
    if (pid_ == 0) {
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      if (!std::freopen("/dev/null", "w", stdout)) _exit(126);
      if (!std::freopen(err.c_str(), "a", stderr)) _exit(126);
      if (fsize > 0) {
        rlimit r{rlim_t(fsize), rlim_t(fsize)};
        setrlimit(RLIMIT_FSIZE, &r);
      }
      execv(argv[0], argv.data());
      _exit(127);
    }
    // The server writes server.json (atomically) once it listens; one that refuses to start exits.
    using namespace std::chrono_literals;
    for (int k = 0; k < 600 && !fs::exists(state_ / "server.json"); ++k) {
      int st = 0;
      if (waitpid(pid_, &st, WNOHANG) == pid_) {
        status_ = st;
        pid_ = -1;
        return;
      }
      std::this_thread::sleep_for(50ms);
    }
    if (const auto info = jobs::read_server_info(state_.string())) address_ = info->listen();
  }
  /// Signal the server and wait for it; returns its wait status.
  int stop(int sig) {
    if (pid_ <= 0) return status_;
    kill(pid_, sig);
    int st = 0;
    waitpid(pid_, &st, 0);
    pid_ = -1;
    status_ = st;
    return st;
  }
  /// The server's wait status once it ended (-1 while it runs).
  int status() const { return status_; }
  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  const std::string& address() const { return address_; }
  std::string errors() const { return read_text(state_.parent_path() / "server.err"); }
  std::string log() const { return read_text(state_.parent_path() / "server.log"); }

 private:
  fs::path state_;
  std::vector<std::string> extra_;
  ServerOptions opt_;
  pid_t pid_ = -1;
  int status_ = -1;
  std::string address_;
};

inline service::ClientOptions client_options(const std::string& address, const std::string& token) {
  service::ClientOptions o;
  o.server = address;
  o.token = token;
  o.watch_timeout_s = 240;  // a broken requeue fails the test instead of hanging it
  return o;
}

}  // namespace runout::test_support
