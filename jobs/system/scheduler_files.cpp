// The scheduler's files in the state directory: where results, logs and checkpoints lie, the job
// records for `runout serve --recover`, the retention policy, and paths of the state directory left
// out of messages to clients (jobs/system/scheduler.hpp has the whole picture).
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>

#include "jobs/system/scheduler.hpp"
#include "jobs/system/state_dir.hpp"

namespace fs = std::filesystem;

namespace runout::jobs {

namespace {

// Seconds since the epoch of "YYYY-MM-DDTHH:MM:SS(.mmm)Z"; 0 when unreadable.
double epoch_of(const std::string& utc) {
  std::tm tm{};
  if (std::sscanf(utc.c_str(), "%d-%d-%dT%d:%d:%d", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min,
                  &tm.tm_sec) != 6)
    return 0;
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return double(timegm(&tm));
}

}  // namespace

std::string Scheduler::checkpoint_path(const std::string& id) const {
  return (fs::path(cfg_.state_dir) / "checkpoints" / (id + ".h5")).string();
}

void Scheduler::remove_checkpoint(const std::string& id) const {
  // The checkpoint and what lies beside it: its frames (.fields.h5, .timeseries.h5), parts (.part).
  std::error_code ec;
  const std::string prefix = id + ".";
  for (const auto& e : fs::directory_iterator(fs::path(cfg_.state_dir) / "checkpoints", ec))
    if (e.path().filename().string().rfind(prefix, 0) == 0) fs::remove(e.path(), ec);
}

std::string Scheduler::results_dir(const std::string& hash) const {
  return (fs::path(cfg_.state_dir) / "results" / hash).string();
}

std::string Scheduler::log_path(const std::string& id) const {
  return (fs::path(cfg_.state_dir) / "logs" / (id + ".log")).string();
}

bool Scheduler::append_job_log(const std::string& id, const std::string& line) const {
  std::ofstream lg(log_path(id), std::ios::app);
  lg << utc_now() << " " << line << "\n";
  lg.flush();
  return bool(lg);
}

void Scheduler::remove_orphan_checkpoints() {
  // A checkpoint is kept only for a job that will run again: one cancelled while it waited in the
  // queue, or ended by the store at a restart (cancel flag, too many attempts), leaves its own.
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(cfg_.state_dir) / "checkpoints", ec)) {
    std::string id = e.path().filename().string();
    id = id.substr(0, id.find('.'));
    std::optional<StoredJob> job;
    try {
      job = store_.get(id);
    } catch (...) {
      continue;
    }
    const bool live = job && (job->job.state() == v1::QUEUED || job->job.state() == v1::RUNNING);
    if (!live) {
      fs::remove(e.path(), ec);
      log("removed the checkpoint file " + e.path().filename().string() + " of a job that will not run again");
    }
  }
}

void Scheduler::apply_retention() {
  std::lock_guard once(retention_mu_);  // one pass at a time
  {
    std::lock_guard lk(mu_);
    last_retention_ = std::chrono::steady_clock::now();
  }
  remove_orphan_checkpoints();
  if (cfg_.retention_days > 0) {  // prepared grids no run has written for that long
    std::error_code ec;
    const auto cutoff = fs::file_time_type::clock::now() - std::chrono::duration_cast<fs::file_time_type::duration>(
                                                                std::chrono::duration<double>(cfg_.retention_days * 86400.0));
    for (const auto& e : fs::directory_iterator(fs::path(cfg_.state_dir) / "cache" / "terrain", ec))
      if (fs::last_write_time(e.path(), ec) < cutoff) fs::remove(e.path(), ec);
  }
  if (cfg_.retention_days <= 0 && cfg_.retention_max_bytes <= 0) return;
  auto finished = store_.finished_results();  // oldest first
  const double now = double(std::time(nullptr));
  std::int64_t total = 0;
  for (const auto& f : finished) total += f.bytes;
  for (const auto& f : finished) {
    const bool old = cfg_.retention_days > 0 && now - epoch_of(f.updated) > cfg_.retention_days * 86400.0;
    const bool over = cfg_.retention_max_bytes > 0 && total > cfg_.retention_max_bytes;
    if (!old && !over) continue;
    std::error_code ec;
    std::lock_guard results_lk(results_mu_);  // not while a job answers from them or moves its own in
    fs::remove_all(results_dir(f.hash), ec);
    total -= f.bytes;
    store_.mark_results_removed(f.hash, old ? "results removed by the retention policy (older than " +
                                                  std::to_string(cfg_.retention_days) + " days)"
                                            : "results removed by the retention policy (disk limit)");
    log("retention: removed results " + f.hash.substr(0, 12) + " (" + std::to_string(f.bytes) + " bytes)");
  }
}

std::string Scheduler::record_path(const std::string& id) const {
  return (fs::path(cfg_.state_dir) / "logs" / (id + ".record.pb")).string();
}

void Scheduler::write_record(const StoredJob& j) const {
  v1::JobRecord rec;
  *rec.mutable_job() = j.job;
  rec.mutable_job()->clear_transitions();
  rec.mutable_job()->clear_progress();
  rec.set_owner(j.owner);
  *rec.mutable_scenario() = j.scenario;
  const std::string path = record_path(j.job.id()), tmp = path + ".tmp";
  std::string bytes;
  rec.SerializeToString(&bytes);
  // Written, synced and renamed, and the folder synced: a record survives a power loss as the store does.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot write the job's record " + path);
  bool ok = ::write(fd, bytes.data(), bytes.size()) == ssize_t(bytes.size()) && ::fsync(fd) == 0;
  ok = ::close(fd) == 0 && ok;
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot write the job's record " + path);
  const int dir = ::open((fs::path(cfg_.state_dir) / "logs").c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

std::string client_message(std::string msg, const std::string& state_dir, const std::vector<std::string>& data_roots) {
  // Uploads are named by the file name the client sent.
  const std::string up = (fs::path(state_dir) / "uploads").string() + "/";
  for (std::size_t at; (at = msg.find(up)) != std::string::npos;) {
    std::size_t end = at + up.size();
    const std::size_t slash = msg.find('/', end);
    if (slash == std::string::npos || slash - end != 64) {
      msg.replace(at, up.size(), "");
      continue;
    }
    msg.erase(at, slash + 1 - at);
  }
  // Files of the run itself are named by their name in the results.
  const std::string res = (fs::path(state_dir) / "results").string() + "/";
  for (std::size_t at; (at = msg.find(res)) != std::string::npos;) {
    const std::size_t slash = msg.find('/', at + res.size());
    msg.erase(at, slash == std::string::npos ? res.size() : slash + 1 - at);
  }
  for (const auto& root : data_roots) {
    const std::string r = (fs::path(root) / "").string();
    for (std::size_t at; !r.empty() && (at = msg.find(r)) != std::string::npos;) msg.erase(at, r.size());
  }
  // Anything else of the state directory by its place in it (checkpoints/..., validate/...).
  const std::string st = (fs::path(state_dir) / "").string();
  for (std::size_t at; (at = msg.find(st)) != std::string::npos;) msg.erase(at, st.size());
  return msg;
}

}  // namespace runout::jobs
