#include "jobs/system/state_dir.hpp"

#include <google/protobuf/util/json_util.h>

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "jobs/system/store.hpp"
#include "runout/v1/worker.pb.h"

namespace fs = std::filesystem;

namespace runout::jobs {

namespace {

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Earlier {
  int results = 0, logs = 0;
};

// Earlier jobs' traces in the state directory.
Earlier earlier_jobs(const fs::path& state) {
  Earlier e;
  std::error_code ec;
  for (const auto& d : fs::directory_iterator(state / "results", ec))
    if (d.path().filename().string().find(".tmp-") == std::string::npos) ++e.results;
  for (const auto& d : fs::directory_iterator(state / "logs", ec)) {
    const std::string n = d.path().filename().string();
    if (d.path().extension() == ".log" || (n.size() > 10 && n.substr(n.size() - 10) == ".record.pb")) ++e.logs;
  }
  return e;
}

// "" when the store is usable, else what is wrong with it.
std::string store_problem(const fs::path& db) {
  std::error_code ec;
  if (!fs::exists(db, ec)) return "is missing";
  if (fs::file_size(db, ec) == 0) return "is empty";
  sqlite3* h = nullptr;
  if (sqlite3_open_v2(db.c_str(), &h, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
    const std::string m = h ? sqlite3_errmsg(h) : "cannot be opened";
    sqlite3_close(h);
    return "cannot be opened (" + m + ")";
  }
  std::string problem;
  sqlite3_stmt* st = nullptr;
  if (sqlite3_prepare_v2(h, "PRAGMA quick_check", -1, &st, nullptr) != SQLITE_OK) {
    problem = std::string("is damaged (") + sqlite3_errmsg(h) + ")";
  } else {
    const int rc = sqlite3_step(st);
    if (rc != SQLITE_ROW) {
      problem = std::string("is damaged (") + sqlite3_errmsg(h) + ")";
    } else {
      const auto* t = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
      const std::string r = t ? t : "";
      if (r != "ok") problem = "is damaged (quick_check: " + r + ")";
    }
  }
  sqlite3_finalize(st);
  if (problem.empty()) {
    // A database, but is it ours?
    if (sqlite3_prepare_v2(h, "SELECT COUNT(*) FROM jobs", -1, &st, nullptr) != SQLITE_OK)
      problem = std::string("is not a runout job store (") + sqlite3_errmsg(h) + ")";
    sqlite3_finalize(st);
  }
  sqlite3_close(h);
  return problem;
}

v1::JobState state_of(const std::string& word) {
  if (word == "queued") return v1::QUEUED;
  if (word == "succeeded") return v1::SUCCEEDED;
  if (word == "failed") return v1::FAILED;
  if (word == "cancelled") return v1::CANCELLED;
  return v1::JOB_STATE_UNSPECIFIED;
}

}  // namespace

std::int64_t folder_bytes(const std::string& path) {
  std::int64_t n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(path, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) n += std::int64_t(it->file_size(ec));
  return n;
}

StateLock::StateLock(const std::string& state_dir) : path_((fs::path(state_dir) / "server.lock").string()) {
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw StateError("state_dir '" + state_dir + "': cannot open its lock file: " + std::strerror(errno));
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    std::string holder = read_file(path_);
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK)
      throw StateError("state_dir '" + state_dir + "' is in use by another runout server (" +
                       (holder.empty() ? std::string("holder unknown") : holder) +
                       "); one server per state directory: stop that one, or give this one another --state-dir");
    throw StateError("state_dir '" + state_dir + "': cannot lock it: " + std::strerror(err));
  }
  set_listen("");
}

StateLock::~StateLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

void StateLock::set_listen(const std::string& address) {
  std::string text = "pid " + std::to_string(getpid());
  if (!address.empty()) text += ", listening on " + address;
  text += "\n";
  if (ftruncate(fd_, 0) != 0) return;
  if (pwrite(fd_, text.data(), text.size(), 0) < 0) return;
}

void check_store(const std::string& state_dir) {
  const fs::path state(state_dir), db = state / "jobs.db";
  const std::string problem = store_problem(db);
  if (problem.empty()) return;
  const Earlier e = earlier_jobs(state);
  const bool missing_or_empty = problem == "is missing" || problem == "is empty";
  if (missing_or_empty && e.results == 0 && e.logs == 0) return;  // a new state directory
  std::string found;
  if (e.results || e.logs)
    found = ", but the state directory holds " + std::to_string(e.results) + " result folder(s) and " + std::to_string(e.logs) +
            " job log(s) or record(s) of earlier jobs";
  throw StateError("job store '" + db.string() + "' " + problem + found +
                   (missing_or_empty ? ": starting would forget those jobs" : "") +
                   ". To rebuild the store from the job records, logs and results, run `runout serve --recover` with the "
                   "same --state-dir (a damaged file is kept beside it); to start afresh, move the state directory away.");
}

std::string RecoveryReport::text() const {
  if (healthy) return "the job store is healthy: nothing to recover";
  std::ostringstream o;
  o << "recovered the job store: " << rebuilt << " job(s) rebuilt from " << records << " record(s) (" << succeeded << " succeeded, "
    << failed << " failed, " << cancelled << " cancelled, " << queued << " queued to run again)";
  if (results_missing) o << "; " << results_missing << " succeeded job(s) whose results are gone are marked removed";
  if (logs_without_record) o << "; " << logs_without_record << " job log(s) without a record could not be rebuilt (their results stay and answer identical submissions)";
  if (!moved_aside.empty()) o << "; the old store is kept as " << moved_aside;
  return o.str();
}

// "2026-11-23T06:30:04.123Z": the time stamp the job system writes (a line without one is not ours).
static bool is_stamp(const std::string& t) {
  if (t.size() != 24 || t[4] != '-' || t[7] != '-' || t[10] != 'T' || t[13] != ':' || t[16] != ':' || t[19] != '.' || t[23] != 'Z')
    return false;
  for (int k : {0, 1, 2, 3, 5, 6, 8, 9, 11, 12, 14, 15, 17, 18, 20, 21, 22})
    if (!std::isdigit(static_cast<unsigned char>(t[std::size_t(k)]))) return false;
  return true;
}

namespace {
const char* const kRequestHead = "request '";
const char* const kRequestTail = "' answered by this job (request digest ";
}  // namespace

std::string request_log_line(const std::string& request_id, const std::string& request_digest) {
  return kRequestHead + request_id + kRequestTail + request_digest + ")";
}

// A job as its record and its log tell it: "TIME attempt N: started ...", "TIME STATE: reason",
// "TIME error: ..." (lines without the job system's time stamp are the worker's own output).
static StoredJob rebuild_job(const v1::JobRecord& rec, const fs::path& state, RecoveryReport& rep) {
  const fs::path logs = state / "logs";
  std::error_code ec;
  StoredJob j;
  j.job = rec.job();
  j.owner = rec.owner();
  j.scenario = rec.scenario();
  const std::string id = j.job.id();
  auto add = [&](v1::JobState s, const std::string& when, const std::string& reason) {
    auto* t = j.job.add_transitions();
    t->set_state(s);
    t->set_time_utc(when);
    t->set_reason(reason);
    j.job.set_state(s);
    j.job.set_updated_utc(when);
  };
  add(v1::QUEUED, j.job.created_utc(), "submitted");
  std::ifstream in(logs / (id + ".log"));
  std::string line;
  int attempts = 0;
  while (std::getline(in, line)) {
    const auto sp = line.find(' ');
    if (sp == std::string::npos) continue;
    const std::string when = line.substr(0, sp), text = line.substr(sp + 1);
    if (!is_stamp(when)) continue;  // the worker's own output (libraries' messages), not the job system's
    if (text.rfind("attempt ", 0) == 0 && text.find(": started") != std::string::npos) {
      ++attempts;
      add(v1::RUNNING, when, "started (attempt " + std::to_string(attempts) + ")");
      continue;
    }
    if (text.rfind(kRequestHead, 0) == 0) {  // a request id answered with this job (request_log_line)
      const auto tail = text.rfind(kRequestTail);
      const std::size_t head = std::string(kRequestHead).size(), after = tail + std::string(kRequestTail).size();
      if (tail != std::string::npos && tail >= head && text.size() == after + 65 && text.back() == ')')
        j.more_requests.emplace_back(text.substr(head, tail - head), text.substr(after, 64));
      continue;
    }
    if (text.rfind("error: ", 0) == 0) {
      j.job.set_error(text.substr(7));
      continue;
    }
    const auto colon = text.find(": ");
    if (colon == std::string::npos) continue;
    const v1::JobState s = state_of(text.substr(0, colon));
    if (s == v1::JOB_STATE_UNSPECIFIED) continue;
    if (s != v1::FAILED) j.job.clear_error();
    if (text.find(": its worker process crashed") != std::string::npos) ++j.crashes;
    add(s, when, text.substr(colon + 2));
  }
  j.job.set_attempts(attempts);
  const std::string now = utc_now();
  if (j.job.state() == v1::RUNNING)
    add(v1::QUEUED, now, "the job store was rebuilt while it ran; queued to run again (from its last checkpoint where it has one)");
  if (j.job.state() == v1::SUCCEEDED) {
    const fs::path res = state / "results" / j.job.scenario_hash();
    if (fs::exists(res / "run.json", ec)) {
      j.job.set_result_bytes(folder_bytes(res.string()));
    } else {
      j.results_removed = true;
      ++rep.results_missing;
    }
  }
  add(j.job.state(), now, "rebuilt by runout serve --recover from the job's record and log");
  return j;
}

RecoveryReport recover_store(const std::string& state_dir, const StateLock& held) {
  (void)held;
  const fs::path state(state_dir), db = state / "jobs.db";
  RecoveryReport rep;
  const std::string problem = store_problem(db);
  if (problem.empty()) {
    rep.healthy = true;
    return rep;
  }
  std::error_code ec;
  // Built beside the store and moved into place when complete.
  const fs::path building = state / "jobs.db.recovering";
  for (const char* side : {"", "-wal", "-shm", "-journal"}) fs::remove(building.string() + side, ec);
  {
    JobStore store(building.string());
    const fs::path logs = state / "logs";
    for (const auto& e : fs::directory_iterator(logs, ec)) {
      const std::string name = e.path().filename().string();
      if (e.path().extension() == ".log") {
        if (!fs::exists(logs / (e.path().stem().string() + ".record.pb"), ec)) ++rep.logs_without_record;
        continue;
      }
      if (name.size() < 10 || name.substr(name.size() - 10) != ".record.pb") continue;
      v1::JobRecord rec;
      const std::string stem = name.substr(0, name.size() - 10);
      if (!rec.ParseFromString(read_file(e.path())) || rec.job().id() != stem || rec.job().scenario_hash().size() != 64 ||
          rec.owner().empty())
        continue;  // not a whole record of this job (cut short, or not ours)
      ++rep.records;
      StoredJob j = rebuild_job(rec, state, rep);
      try {
        store.insert_recovered(j);
      } catch (const std::exception&) {
        continue;  // a duplicate record (cannot happen: one file per id)
      }
      ++rep.rebuilt;
      switch (j.job.state()) {
        case v1::SUCCEEDED: ++rep.succeeded; break;
        case v1::FAILED: ++rep.failed; break;
        case v1::CANCELLED: ++rep.cancelled; break;
        default: ++rep.queued; break;
      }
    }
  }  // the new store is closed (its WAL folded in)
  if (fs::exists(db, ec)) {
    rep.moved_aside = db.string() + ".damaged-" + utc_now();
    fs::rename(db, rep.moved_aside, ec);
    if (ec) throw StateError("cannot move the damaged store aside: " + ec.message());
  }
  for (const char* side : {"-wal", "-shm"}) {
    const fs::path p = db.string() + side;
    if (fs::exists(p, ec)) {
      if (!rep.moved_aside.empty()) fs::rename(p, rep.moved_aside + side, ec);
      else fs::remove(p, ec);
    }
  }
  fs::rename(building, db, ec);
  if (ec) throw StateError("cannot move the rebuilt store into place: " + ec.message());
  return rep;
}

void write_server_info(const std::string& state_dir, const v1::ServerInfo& info) {
  std::string json;
  google::protobuf::util::JsonPrintOptions o;
  o.preserve_proto_field_names = true;
  if (!google::protobuf::util::MessageToJsonString(info, &json, o).ok()) throw StateError("server.json: cannot write it as JSON");
  const fs::path dir(state_dir), tmp = dir / "server.json.tmp";
  {
    std::ofstream out(tmp);
    out << json << "\n";
    if (!out) throw StateError("cannot write '" + tmp.string() + "'");
  }
  fs::rename(tmp, dir / "server.json");
}

std::optional<v1::ServerInfo> read_server_info(const std::string& state_dir) {
  std::ifstream in(fs::path(state_dir) / "server.json");
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  v1::ServerInfo info;
  if (!google::protobuf::util::JsonStringToMessage(ss.str(), &info).ok() || info.listen().empty()) return std::nullopt;
  return info;
}

}  // namespace runout::jobs
