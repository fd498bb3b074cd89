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
#include <cstring>
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

WorkerProcess::WorkerProcess(const std::string& exe, const v1::WorkerTask& task, const std::string& log_path) {
  std::signal(SIGPIPE, SIG_IGN);  // a worker that dies before reading its task must not take us down
  int in[2], out[2];
  if (pipe2(in, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot start a worker: pipe: ") + std::strerror(errno));
  if (pipe2(out, O_CLOEXEC) != 0) {
    close(in[0]);
    close(in[1]);
    throw std::runtime_error(std::string("cannot start a worker: pipe: ") + std::strerror(errno));
  }
  const int log = ::open(log_path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  std::string a0 = exe, a1 = "worker";
  char* argv[] = {a0.data(), a1.data(), nullptr};
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
    execv(argv[0], argv);
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
  ::kill(pid_, sig);
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

std::int64_t WorkerProcess::resident_bytes() const {
  std::ifstream f("/proc/" + std::to_string(pid_) + "/statm");
  long size = 0, resident = 0;
  if (!(f >> size >> resident)) return 0;
  return std::int64_t(resident) * sysconf(_SC_PAGESIZE);
}

}  // namespace runout::jobs
