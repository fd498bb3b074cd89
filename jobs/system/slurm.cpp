#include "jobs/system/slurm.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace fs = std::filesystem;

namespace runout::jobs {

namespace {

// A path in single quotes for sh.
std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// "Key=Value" of scontrol's one-line output; "" when absent.
std::string field(const std::string& line, const std::string& key) {
  std::istringstream in(line);
  for (std::string tok; in >> tok;)
    if (tok.rfind(key + "=", 0) == 0) return tok.substr(key.size() + 1);
  return "";
}

bool is_final(const std::string& state) {
  for (const char* s : {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY", "BOOT_FAIL", "DEADLINE", "PREEMPTED"})
    if (state == s) return true;
  return false;
}

}  // namespace

SlurmSubmitter::SlurmSubmitter(std::string dir, SlurmConfig cfg) : dir_(std::move(dir)), cfg_(std::move(cfg)) {
  fs::create_directories(dir_);
}

std::string SlurmSubmitter::command(const std::string& name, const std::vector<std::string>& args, int& rc, std::string* err) const {
  const std::string exe = cfg_.commands_dir.empty() ? name : (fs::path(cfg_.commands_dir) / name).string();
  int out[2];
  if (pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot run ") + name + ": " + std::strerror(errno));
  // Standard error apart (sites' submit filters print notes there): parsed output is standard output only.
  char errpath[] = "/tmp/runout-slurm-err-XXXXXX";
  const int efd = mkostemp(errpath, O_CLOEXEC);
  if (efd >= 0) ::unlink(errpath);
  std::vector<std::string> a = {exe};
  a.insert(a.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& x : a) argv.push_back(x.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) {
    close(out[0]);
    close(out[1]);
    if (efd >= 0) close(efd);
    throw std::runtime_error(std::string("cannot run ") + name + ": fork: " + std::strerror(errno));
  }
  if (pid == 0) {
    dup2(out[1], 1);
    if (efd >= 0) dup2(efd, 2);
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) dup2(null, 0);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  close(out[1]);
  std::string text;
  char b[4096];
  for (ssize_t n; (n = ::read(out[0], b, sizeof b)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    text.append(b, std::size_t(n));
  }
  close(out[0]);
  int st = 0;
  while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
  }
  rc = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  std::string etext;
  if (efd >= 0) {
    lseek(efd, 0, SEEK_SET);
    for (ssize_t n; (n = ::read(efd, b, sizeof b)) > 0;) etext.append(b, std::size_t(n));
    close(efd);
  }
  if (rc == 127) etext = name + ": not found (Slurm's client commands are needed: apt-get install slurm-client)";
  if (err) *err = etext;
  return text;
}

SlurmSubmitter::Submitted SlurmSubmitter::submit(const v1::WorkerTask& task, const std::string& log_path) {
  auto p = std::make_shared<Pending>();
  p->task = task;
  p->log_path = log_path;
  std::unique_lock lk(mu_);
  pending_.push_back(p);
  if (!leader_) {
    // The first of a batch waits for the others, then submits them all as one array.
    leader_ = true;
    lk.unlock();
    std::this_thread::sleep_for(std::chrono::milliseconds(long(cfg_.batch_window_s * 1000)));
    lk.lock();
    auto batch = std::move(pending_);
    pending_.clear();
    leader_ = false;
    lk.unlock();
    // An array's tasks share its --ntasks: a task over several MPI ranks goes into an array with
    // those of the same ranks.
    std::map<int, std::vector<std::shared_ptr<Pending>>> by_ranks;
    for (auto& q : batch) by_ranks[std::max(1, q->task.ranks())].push_back(q);
    for (auto& [ranks, group] : by_ranks) submit_batch(group);
    lk.lock();
    cv_.notify_all();
  }
  cv_.wait(lk, [&] { return p->done; });
  if (!p->error.empty()) throw std::runtime_error(p->error);
  return p->out;
}

void SlurmSubmitter::submit_batch(std::vector<std::shared_ptr<Pending>> batch) {
  std::string error;
  std::string dir;
  try {
    long seq;
    {
      std::lock_guard lk(mu_);
      seq = ++arrays_;
    }
    // A name no earlier server used (a container's server often has the same pid every time).
    std::random_device rd;
    char tag[20];
    std::snprintf(tag, sizeof tag, "%08x", unsigned(rd()));
    dir = (fs::path(dir_) / (std::to_string(getpid()) + "-" + std::to_string(seq) + "-" + tag)).string();
    if (!fs::create_directories(dir)) throw std::runtime_error("the job array's folder " + dir + " exists already");
    {
      std::lock_guard lk(mu_);
      open_[dir] = int(batch.size());
    }
    int threads = 1;
    const int ranks = std::max(1, batch.front()->task.ranks());
    for (std::size_t k = 0; k < batch.size(); ++k) {
      std::string bytes;
      batch[k]->task.SerializeToString(&bytes);
      std::ofstream(fs::path(dir) / (std::to_string(k) + ".task"), std::ios::binary) << bytes;
      std::ofstream(fs::path(dir) / (std::to_string(k) + ".log")) << batch[k]->log_path;
      threads = std::max(threads, batch[k]->task.threads());
    }
    // Each task: its task file in, its events out (a file per Slurm attempt), its log appended. A
    // task over several MPI ranks is one srun step of that many tasks, the task file to rank 0.
    const std::string script = (fs::path(dir) / "run.sh").string();
    std::string launch;
    if (ranks > 1) {
      launch = "srun --ntasks=" + std::to_string(ranks) + " --cpus-per-task=" + std::to_string(threads) + " --input=0";
      if (cfg_.mpi != "cluster") launch += " --mpi=" + cfg_.mpi;  // (a plugin's name: letters, digits, _)
      launch += " ";
    }
    std::ofstream(script) << "#!/bin/sh\n"
                          << "d=" << quoted(dir) << "\n"
                          << "k=\"$SLURM_ARRAY_TASK_ID\"\n"
                          << "exec " << launch << quoted(cfg_.worker_exe) << " worker < \"$d/$k.task\" >> \"$d/$k.events.${SLURM_RESTART_COUNT:-0}\""
                          << " 2>> \"$(cat \"$d/$k.log\")\"\n";
    fs::permissions(script, fs::perms::owner_all | fs::perms::group_read | fs::perms::others_read);
    std::vector<std::string> args = {"--parsable", "--array=0-" + std::to_string(batch.size() - 1), "--job-name=" + cfg_.job_name,
                                     "--chdir=" + dir, "--output=" + (fs::path(dir) / "slurm-%A_%a.out").string(),
                                     "--open-mode=append", "--requeue", "--ntasks=" + std::to_string(ranks),
                                     "--cpus-per-task=" + std::to_string(threads)};
    if (!cfg_.partition.empty()) args.push_back("--partition=" + cfg_.partition);
    args.insert(args.end(), cfg_.sbatch_args.begin(), cfg_.sbatch_args.end());
    args.push_back(script);
    int rc = 0;
    std::string err;
    const std::string out = command("sbatch", args, rc, &err);
    // --parsable: the job id (";cluster"), the last such line (a site's filter may print before it).
    std::string id;
    std::istringstream lines(out);
    for (std::string l; std::getline(lines, l);) {
      const std::string head = l.substr(0, l.find(';'));
      if (!head.empty() && head.find_first_not_of("0123456789") == std::string::npos) id = head;
    }
    if (rc != 0 || id.empty())
      throw std::runtime_error("Slurm refused the job array (sbatch exit status " + std::to_string(rc) + "): " + err + out);
    for (std::size_t k = 0; k < batch.size(); ++k) batch[k]->out = {id + "_" + std::to_string(k), dir, int(k)};
  } catch (const std::exception& e) {
    error = e.what();
  }
  std::lock_guard lk(mu_);
  for (auto& p : batch) {
    p->error = error;
    p->done = true;
  }
}

void SlurmSubmitter::cancel_all() {
  int rc = 0;
  command("scancel", {"--name=" + cfg_.job_name}, rc);
  // They end at their step (with a checkpoint); their jobs run again only once none is left, so
  // that no old task writes beside the new attempt.
  for (int k = 0; k < 600; ++k) {
    const std::string out = command("squeue", {"-h", "--name=" + cfg_.job_name, "-o", "%i"}, rc);
    if (rc != 0 || out.find_first_not_of(" \n") == std::string::npos) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

void SlurmSubmitter::release(const std::string& dir) {
  std::lock_guard lk(mu_);
  const auto it = open_.find(dir);
  if (it == open_.end() || --it->second > 0) return;
  open_.erase(it);
  std::error_code ec;
  fs::remove_all(dir, ec);  // every task of the array has ended: its files go
}

SlurmStep::SlurmStep(SlurmSubmitter& s, const v1::WorkerTask& task, const std::string& log_path)
    : s_(s), sub_(s.submit(task, log_path)), ranks_(std::max(1, task.ranks())) {}

SlurmStep::~SlurmStep() {
  if (!final_) {  // followed no further (the scheduler gave up on it): it must not run on unseen
    int rc = 0;
    try {
      s_.command("scancel", {sub_.id}, rc);
    } catch (...) {
    }
  }
  s_.release(sub_.dir);
}

void SlurmStep::poll_state() {
  last_poll_ = std::chrono::steady_clock::now();
  int rc = 0;
  std::string err;
  const std::string out = s_.command("scontrol", {"show", "job", "-o", sub_.id}, rc, &err);
  if (rc != 0) {
    // Slurm forgets an ended job after MinJobAge: it has ended, and its events say how.
    if ((err + out).find("Invalid job id") != std::string::npos) final_ = gone_ = true;
    return;
  }
  std::string line;
  std::istringstream lines(out);
  for (std::string l; std::getline(lines, l);)
    if (l.find("JobId=") != std::string::npos) {
      line = l;
      break;
    }
  if (line.empty()) return;
  state_ = field(line, "JobState");
  exit_code_ = field(line, "ExitCode");
  const std::string r = field(line, "Restarts");
  if (!r.empty() && r.find_first_not_of("0123456789") == std::string::npos) restarts_ = std::stoi(r);
  final_ = is_final(state_);
}

bool SlurmStep::read_more() {
  if (restarts_ > reading_) {  // Slurm ran the task again (its node failed): the new attempt's events
    reading_ = restarts_;
    offset_ = 0;
    buf_.clear();
  }
  std::ifstream f(fs::path(sub_.dir) / (std::to_string(sub_.index) + ".events." + std::to_string(reading_)), std::ios::binary);
  if (!f) return false;
  f.seekg(std::streamoff(offset_));
  char b[65536];
  bool got = false;
  while (f.read(b, sizeof b) || f.gcount() > 0) {
    buf_.append(b, std::size_t(f.gcount()));
    offset_ += std::size_t(f.gcount());
    got = true;
  }
  return got;
}

std::optional<v1::WorkerEvent> SlurmStep::next_event(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (auto ev = take_event(buf_, closed_)) return ev;
    if (closed_) return std::nullopt;
    if (read_more()) continue;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_poll_ > std::chrono::seconds(1)) {
      const bool was_final = final_;
      poll_state();
      if (was_final && final_ && !read_more()) {  // ended, and every event it wrote has been read
        closed_ = true;
        return std::nullopt;
      }
      continue;
    }
    if (now >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::min(std::chrono::milliseconds(50),
                                         std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now)));
  }
}

void SlurmStep::signal(int sig) {
  int rc = 0;
  if (sig == SIGTERM && state_ == "RUNNING") {
    // The worker ends at its step, with a checkpoint: the batch step is the worker, or, for a task
    // over MPI ranks, srun, whose step's tasks (the ranks) get the signal.
    if (ranks_ > 1)
      s_.command("scancel", {"--signal=TERM", sub_.id}, rc);
    else
      s_.command("scancel", {"--signal=TERM", "--batch", sub_.id}, rc);
  } else {
    s_.command("scancel", {sub_.id}, rc);
  }
  sent_ = sig;
}

std::optional<WorkerExit> SlurmStep::wait(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!final_) {
    poll_state();
    if (final_ || std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  if (!final_) return std::nullopt;
  WorkerExit e;
  const auto colon = exit_code_.find(':');
  const int code = std::atoi(exit_code_.substr(0, colon).c_str());
  const int sig = colon == std::string::npos ? 0 : std::atoi(exit_code_.substr(colon + 1).c_str());
  if (gone_ || state_ == "COMPLETED") {
    e.exited = true;
    e.code = code;
  } else if (state_ == "FAILED") {
    e.exited = sig == 0;
    e.code = code;
    e.signal = sig;
    e.signal_ours = sent_ != 0;
  } else if (state_ == "CANCELLED" || state_ == "PREEMPTED" || state_ == "NODE_FAIL" || state_ == "BOOT_FAIL") {
    // Cancelled by someone else, preempted, or its node failed without Slurm running it again:
    // stopped from outside (queued again, not counted against the job).
    e.signal = sent_ ? sent_ : SIGTERM;
    e.signal_ours = sent_ != 0;
  } else {  // memory or time ran out: killed
    e.signal = SIGKILL;
    e.signal_ours = false;
  }
  if (state_ != "COMPLETED" && state_ != "FAILED" && !gone_) {
    int rc = 0;
    s_.command("scancel", {sub_.id}, rc);  // nothing of it may run on while its job runs again
  }
  return e;
}

}  // namespace runout::jobs
