#include "jobs/system/worker.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <vector>


namespace runout::jobs {

namespace {

std::string signal_name(int sig) {
  switch (sig) {
    case SIGSEGV: return "SIGSEGV";
    case SIGABRT: return "SIGABRT";
    case SIGKILL: return "SIGKILL";
    case SIGTERM: return "SIGTERM";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGXFSZ: return "SIGXFSZ";
    case SIGINT: return "SIGINT";
    default: return "signal " + std::to_string(sig);
  }
}

}  // namespace

std::string WorkerExit::describe() const { return exited ? "exit status " + std::to_string(code) : signal_name(signal); }

std::string self_executable() {
  // The link itself, not where it points: exec of it starts this very program even after its file
  // was replaced or removed by an upgrade (the path would then read "... (deleted)").
  return "/proc/self/exe";
}

namespace {

// Whether a command (a path, or a name on PATH) is an executable file.
bool on_path(const std::string& cmd) {
  if (cmd.find('/') != std::string::npos) return ::access(cmd.c_str(), X_OK) == 0;
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  for (std::size_t at = 0; at <= dirs.size();) {
    const std::size_t end = std::min(dirs.find(':', at), dirs.size());
    const std::string dir = dirs.substr(at, end - at);
    if (::access(((dir.empty() ? "." : dir) + "/" + cmd).c_str(), X_OK) == 0) return true;
    at = end + 1;
  }
  return false;
}

// The worker's command line: `EXE worker`, or under a launcher for a task over several MPI ranks
// `LAUNCHER... -n RANKS EXE worker`. The launcher starts EXE in processes of its own, where
// /proc/self/exe would name the launcher: it gets the program's own path.
std::vector<std::string> worker_command(const std::string& exe, const v1::WorkerTask& task, const std::vector<std::string>& launcher) {
  if (task.ranks() <= 1 || launcher.empty()) return {exe, "worker"};
  std::error_code ec;
  std::string path = exe;
  if (exe == "/proc/self/exe") {
    path = std::filesystem::read_symlink(exe, ec).string();
    if (ec) throw std::runtime_error("cannot start a worker over MPI ranks: the program's path: " + ec.message());
  }
  if (!on_path(launcher.front()))
    throw std::runtime_error("cannot start a job over " + std::to_string(task.ranks()) + " MPI ranks: the launcher '" + launcher.front() +
                             "' was not found (Debian: apt-get install openmpi-bin; the server's mpi_launcher)");
  std::vector<std::string> a = launcher;
  for (const std::string& x : {std::string("-n"), std::to_string(task.ranks()), path, std::string("worker")}) a.push_back(x);
  return a;
}

// Resident memory of a process [bytes] (0 when it cannot be read).
std::int64_t process_resident(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/statm");
  long size = 0, resident = 0;
  return (f >> size >> resident) ? std::int64_t(resident) * sysconf(_SC_PAGESIZE) : 0;
}

// Of a process and every process below it: a launcher's ranks count.
std::int64_t tree_resident(pid_t pid, int depth) {
  std::int64_t total = process_resident(pid);
  if (depth > 8) return total;
  std::ifstream c("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
  for (long child; c >> child;) total += tree_resident(pid_t(child), depth + 1);
  return total;
}

}  // namespace

WorkerProcess::WorkerProcess(const std::string& exe, const v1::WorkerTask& task, const std::string& log_path,
                             const std::vector<std::string>& launcher) {
  std::vector<std::string> args = worker_command(exe, task, launcher);
  launched_ = args.size() > 2;
  std::signal(SIGPIPE, SIG_IGN);  // a worker that dies before reading its task must not take us down
  int in[2], out[2];
  if (pipe2(in, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot start a worker: pipe: ") + std::strerror(errno));
  if (pipe2(out, O_CLOEXEC) != 0) {
    close(in[0]);
    close(in[1]);
    throw std::runtime_error(std::string("cannot start a worker: pipe: ") + std::strerror(errno));
  }
  const int log = ::open(log_path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  std::vector<char*> argv;
  for (auto& x : args) argv.push_back(x.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    // Only async-signal-safe calls from here to exec.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    setpgid(0, 0);  // a terminal's Ctrl-C or a signal to the server's group reaches the server, which decides
    dup2(in[0], 0);
    dup2(out[1], 1);
    if (log >= 0) dup2(log, 2);
    if (close_range(3, ~0U, 0) != 0)
      for (int fd = 3; fd < 4096; ++fd) close(fd);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);  // the server blocks SIGTERM/SIGINT in its threads
    ::signal(SIGPIPE, SIG_DFL);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  const int err = errno;
  close(in[0]);
  close(out[1]);
  if (log >= 0) close(log);
  if (pid < 0) {
    close(in[1]);
    close(out[0]);
    throw std::runtime_error(std::string("cannot start a worker: fork: ") + std::strerror(err));
  }
  pid_ = pid;
  out_fd_ = out[0];
  fcntl(out_fd_, F_SETFL, fcntl(out_fd_, F_GETFL) | O_NONBLOCK);
  // The task goes in as the worker reads it (a task can be larger than the pipe's buffer, and a
  // worker that never reads must not block us): what does not fit now is written by fill().
  in_fd_ = in[1];
  fcntl(in_fd_, F_SETFL, fcntl(in_fd_, F_GETFL) | O_NONBLOCK);
  task.SerializeToString(&pending_in_);
  feed();
}

void WorkerProcess::feed() {
  while (in_fd_ >= 0 && !pending_in_.empty()) {
    const ssize_t w = ::write(in_fd_, pending_in_.data(), pending_in_.size());
    if (w > 0) {
      pending_in_.erase(0, std::size_t(w));
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno == EAGAIN) return;
    pending_in_.clear();  // the worker is gone: wait() tells
  }
  if (in_fd_ >= 0 && pending_in_.empty()) {
    close(in_fd_);
    in_fd_ = -1;
  }
}

WorkerProcess::~WorkerProcess() {
  if (!reaped_ && pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int st = 0;
    while (waitpid(pid_, &st, 0) < 0 && errno == EINTR) {
    }
  }
  if (out_fd_ >= 0) close(out_fd_);
  if (in_fd_ >= 0) close(in_fd_);
}

bool WorkerProcess::fill(std::chrono::milliseconds timeout) {
  if (closed_) return false;
  pollfd p[2] = {{out_fd_, POLLIN, 0}, {in_fd_, POLLOUT, 0}};
  const int r = poll(p, in_fd_ >= 0 ? 2 : 1, int(timeout.count()));
  if (r <= 0) return false;
  if (in_fd_ >= 0 && p[1].revents) feed();
  if (!p[0].revents) return false;
  char b[65536];
  bool got = false;
  for (;;) {
    const ssize_t n = ::read(out_fd_, b, sizeof b);
    if (n > 0) {
      buf_.append(b, std::size_t(n));
      got = true;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n == 0) closed_ = true;
    break;  // EAGAIN: all there is for now
  }
  return got;
}

std::optional<v1::WorkerEvent> WorkerProcess::next_event(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (auto ev = take_event(buf_, closed_)) return ev;
    if (closed_) return std::nullopt;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return std::nullopt;
    fill(left);
  }
}

void WorkerProcess::signal(int sig) {
  if (reaped_ || pid_ <= 0) return;
  sent_ = true;
  // A launcher answers SIGTERM by killing its ranks within seconds; SIGUSR1 it passes on to every
  // rank, which ends at the end of its step (with the checkpoint) as a worker does on SIGTERM.
  ::kill(pid_, launched_ && sig == SIGTERM ? SIGUSR1 : sig);
}

void WorkerProcess::stop(std::chrono::milliseconds grace) {
  signal(SIGTERM);
  if (!wait(grace)) signal(SIGKILL);
}

std::optional<WorkerExit> WorkerProcess::wait(std::chrono::milliseconds timeout) {
  if (reaped_) return exit_;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int st = 0;
    const pid_t r = waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
      reaped_ = true;
      exit_.exited = WIFEXITED(st);
      exit_.code = exit_.exited ? WEXITSTATUS(st) : 0;
      exit_.signal = WIFSIGNALED(st) ? WTERMSIG(st) : 0;
      exit_.signal_ours = sent_ && (exit_.signal == SIGTERM || exit_.signal == SIGKILL);
      return exit_;
    }
    if (r < 0 && errno != EINTR) {
      reaped_ = true;  // not our child any more (cannot happen unless reaped elsewhere)
      exit_.exited = true;
      exit_.code = 127;
      return exit_;
    }
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    // Drain the output meanwhile, so that a worker blocked on a full pipe can end.
    if (!closed_) fill(std::chrono::milliseconds(20));
    else std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::int64_t WorkerProcess::resident_bytes() const { return launched_ ? tree_resident(pid_, 0) : process_resident(pid_); }

}  // namespace runout::jobs
