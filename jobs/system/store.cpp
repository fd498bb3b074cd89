#include "jobs/system/store.hpp"
#include "jobs/system/store_sql.hpp"

#include <sqlite3.h>

#include <chrono>
#include <ctime>
#include <random>

namespace runout::jobs {

namespace {

using sql::Stmt;
using sql::Transaction;

constexpr const char* kColumns =
    "id, owner, name, hash, request_id, state, created, updated, error, attempts, scenario, progress, result_bytes, "
    "results_removed, crashes, parent, member";
constexpr int kNextColumn = 17;  // the first column a query adds after kColumns
// The job a request id (?2) of a client (?1) names: the one it created, or the earlier identical one
// that answered it (table requests); the one it created first.
constexpr const char* kNamedByRequest =
    " FROM jobs WHERE owner = ?1 AND (request_id = ?2 OR id = (SELECT job FROM requests WHERE owner = ?1 AND request_id = ?2)) "
    "ORDER BY request_id IS ?2 DESC LIMIT 1";

void add_transition(sqlite3* db, const std::string& id, v1::JobState s, const std::string& when, const std::string& reason) {
  Stmt(db, "INSERT INTO transitions(job, time, state, reason) VALUES (?, ?, ?, ?)")
      .bind(1, id)
      .bind(2, when)
      .bind(3, std::int64_t(s))
      .bind(4, reason)
      .step();
}

// A new queued job (and its "submitted" transition); `parent` empty and `member` -1 for a job of its own.
void insert_job(sqlite3* db, const std::string& id, const std::string& owner, const std::string& name, const std::string& hash,
                const std::string& request_id, const v1::Scenario& scenario, const std::string& request_hash, const std::string& now,
                const std::string& parent = "", int member = -1) {
  std::string blob;
  scenario.SerializeToString(&blob);
  Stmt ins(db,
           "INSERT INTO jobs(id, owner, name, hash, request_id, state, created, updated, scenario, request_hash, parent, member) "
           "VALUES (?, ?, ?, ?, ?, 1, ?, ?, ?, ?, ?, ?)");
  ins.bind(1, id).bind(2, owner).bind(3, name).bind(4, hash);
  if (request_id.empty())
    ins.null(5);
  else
    ins.bind(5, request_id);
  ins.bind(6, now).bind(7, now).blob(8, blob);
  if (request_hash.empty())
    ins.null(9);
  else
    ins.bind(9, request_hash);
  ins.bind(10, parent).bind(11, std::int64_t(member));
  ins.step();
  add_transition(db, id, v1::QUEUED, now, "submitted");
}

// The job as submit() returns it after insert_job.
StoredJob queued_job(const std::string& id, const std::string& owner, const std::string& name, const std::string& hash,
                     const std::string& request_id, const v1::Scenario& scenario, const std::string& now) {
  StoredJob out;
  out.owner = owner;
  out.scenario = scenario;
  auto& j = out.job;
  j.set_id(id);
  j.set_state(v1::QUEUED);
  j.set_name(name);
  j.set_scenario_hash(hash);
  j.set_created_utc(now);
  j.set_updated_utc(now);
  j.set_request_id(request_id);
  auto* t = j.add_transitions();
  t->set_state(v1::QUEUED);
  t->set_time_utc(now);
  t->set_reason("submitted");
  return out;
}

}  // namespace

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[64];
  std::snprintf(b, sizeof b, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour,
                tm.tm_min, tm.tm_sec, int(ms));
  return b;
}

std::string new_job_id() {
  static thread_local std::mt19937_64 rng{std::random_device{}() ^
                                          std::uint64_t(std::chrono::steady_clock::now().time_since_epoch().count())};
  char b[24];
  std::snprintf(b, sizeof b, "j%016llx", static_cast<unsigned long long>(rng()));
  return b;
}

std::string state_name(v1::JobState s) {
  switch (s) {
    case v1::QUEUED: return "queued";
    case v1::RUNNING: return "running";
    case v1::SUCCEEDED: return "succeeded";
    case v1::FAILED: return "failed";
    case v1::CANCELLED: return "cancelled";
    default: return "unknown";
  }
}

bool is_final(v1::JobState s) { return s == v1::SUCCEEDED || s == v1::FAILED || s == v1::CANCELLED; }

StoredJob JobStore::read_row(void* p) const {
  auto* st = static_cast<Stmt*>(p);
  StoredJob j;
  j.job.set_id(st->text(0));
  j.owner = st->text(1);
  j.job.set_name(st->text(2));
  j.job.set_scenario_hash(st->text(3));
  j.job.set_request_id(st->text(4));
  j.job.set_state(v1::JobState(st->i64(5)));
  j.job.set_created_utc(st->text(6));
  j.job.set_updated_utc(st->text(7));
  j.job.set_error(st->text(8));
  j.job.set_attempts(int(st->i64(9)));
  if (!j.scenario.ParseFromString(st->text(10))) throw StoreError("job store: job " + j.job.id() + " holds an unreadable scenario");
  const std::string prog = st->text(11);
  if (!prog.empty()) (void)j.job.mutable_progress()->ParseFromString(prog);
  j.job.set_result_bytes(st->i64(12));
  j.results_removed = st->i64(13) != 0;
  j.crashes = int(st->i64(14));
  j.job.set_parent_id(st->text(15));
  j.job.set_member_index(int(st->i64(16)));
  return j;
}

void JobStore::load_transitions(StoredJob& j) const {
  Stmt st(db_, "SELECT time, state, reason FROM transitions WHERE job = ? ORDER BY rowid");
  st.bind(1, j.job.id());
  while (st.step()) {
    auto* t = j.job.add_transitions();
    t->set_time_utc(st.text(0));
    t->set_state(v1::JobState(st.i64(1)));
    t->set_reason(st.text(2));
  }
}

SubmitOutcome JobStore::submit(const std::string& owner, const std::string& hash, const std::string& request_id,
                               const v1::Scenario& scenario, int max_queued, const std::string& request_hash) {
  return submit_ensemble(owner, hash, request_id, scenario, {}, max_queued, request_hash);
}

SubmitOutcome JobStore::submit_ensemble(const std::string& owner, const std::string& hash, const std::string& request_id,
                                        const v1::Scenario& scenario, const std::vector<NewMember>& members, int max_queued,
                                        const std::string& request_hash,
                                        const std::function<void(const StoredJob&)>& record_request) {
  std::lock_guard lk(mu_);
  Transaction tx(db_);
  SubmitOutcome out;
  auto existing = [&](Stmt& st) {
    if (!st.step()) return false;
    out.job = read_row(&st);
    load_transitions(out.job);
    fill_counts(out.job);
    return true;
  };
  if (!request_id.empty()) {
    Stmt st(db_, (std::string("SELECT ") + kColumns + kNamedByRequest).c_str());
    st.bind(1, owner).bind(2, request_id);
    if (existing(st)) {
      if (out.job.job.scenario_hash() != hash)
        throw RequestIdConflict("request_id '" + request_id + "' was used for job " + out.job.job.id() +
                                " with another scenario; use a new request id for a new scenario");
      tx.commit();
      return out;
    }
  }
  {
    Stmt st(db_, (std::string("SELECT ") + kColumns +
                  " FROM jobs WHERE owner = ? AND hash = ? AND state IN (1, 2, 3) AND results_removed = 0 AND parent = '' "
                  "ORDER BY seq DESC LIMIT 1")
                     .c_str());
    st.bind(1, owner).bind(2, hash);
    if (existing(st)) {
      if (!request_id.empty()) {  // from now on the request id names this job (a retry, or another scenario: refused)
        Stmt(db_, "INSERT INTO requests(owner, request_id, job, request_hash) VALUES (?, ?, ?, ?)")
            .bind(1, owner).bind(2, request_id).bind(3, out.job.job.id()).bind(4, request_hash).step();
        if (record_request) record_request(out.job);
      }
      tx.commit();
      return out;
    }
  }
  {
    // An ensemble counts once: its members are not the client's submissions.
    Stmt st(db_, "SELECT COUNT(*) FROM jobs WHERE owner = ? AND state IN (1, 2) AND parent = ''");
    st.bind(1, owner);
    st.step();
    if (st.i64(0) >= max_queued)
      throw QueueFull("this client already has " + std::to_string(st.i64(0)) + " queued or running jobs (the server's limit is " +
                      std::to_string(max_queued) + ")");
  }
  const std::string id = new_job_id(), now = utc_now();
  insert_job(db_, id, owner, scenario.name(), hash, request_id, scenario, request_hash, now);
  for (const auto& m : members) {
    const std::string name = scenario.name() + " [member " + std::to_string(m.index + 1) + " of " + std::to_string(members.size()) + "]";
    insert_job(db_, new_job_id(), owner, name, m.hash, "", m.scenario, "", now, id, m.index);
  }
  tx.commit();
  out.created = true;
  out.job = queued_job(id, owner, scenario.name(), hash, request_id, scenario, now);
  if (!members.empty()) fill_counts(out.job);
  return out;
}

std::optional<StoredJob> JobStore::get(const std::string& id, const std::string& owner) const {
  std::lock_guard lk(mu_);
  Stmt st(db_, (std::string("SELECT ") + kColumns + " FROM jobs WHERE id = ?").c_str());
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  StoredJob j = read_row(&st);
  if (!owner.empty() && j.owner != owner) return std::nullopt;
  load_transitions(j);
  fill_counts(j);
  return j;
}

void JobStore::fill_counts(StoredJob& j) const {
  Stmt st(db_, "SELECT state, COUNT(*) FROM jobs WHERE parent = ? GROUP BY state");
  st.bind(1, j.job.id());
  v1::EnsembleCounts c;
  while (st.step()) {
    const int n = int(st.i64(1));
    c.set_total(c.total() + n);
    switch (v1::JobState(st.i64(0))) {
      case v1::QUEUED: c.set_queued(n); break;
      case v1::RUNNING: c.set_running(n); break;
      case v1::SUCCEEDED: c.set_succeeded(n); break;
      case v1::FAILED: c.set_failed(n); break;
      case v1::CANCELLED: c.set_cancelled(n); break;
      default: break;
    }
  }
  if (c.total() > 0) *j.job.mutable_members() = c;
}

std::vector<StoredJob> JobStore::members(const std::string& parent) const {
  std::lock_guard lk(mu_);
  Stmt st(db_, (std::string("SELECT ") + kColumns + " FROM jobs WHERE parent = ? ORDER BY member").c_str());
  st.bind(1, parent);
  std::vector<StoredJob> out;
  while (st.step()) out.push_back(read_row(&st));
  return out;
}

std::vector<StoredJob> JobStore::list(const std::string& owner, const std::vector<v1::JobState>& states, int page_size,
                                      const std::string& page_token, std::string* next_page_token) const {
  std::lock_guard lk(mu_);
  std::string sql = std::string("SELECT ") + kColumns + ", seq FROM jobs WHERE owner = ? AND seq < ? AND parent = ''";
  if (!states.empty()) {
    sql += " AND state IN (";
    for (std::size_t k = 0; k < states.size(); ++k) sql += (k ? ", " : "") + std::to_string(int(states[k]));
    sql += ")";
  }
  sql += " ORDER BY seq DESC LIMIT ?";
  std::int64_t before = INT64_MAX;
  if (!page_token.empty()) {
    try {
      before = std::stoll(page_token);
    } catch (...) {
      throw std::invalid_argument("page_token: not a token this server gave out");
    }
  }
  Stmt st(db_, sql.c_str());
  st.bind(1, owner).bind(2, before).bind(3, std::int64_t(page_size) + 1);
  std::vector<StoredJob> out;
  std::int64_t last_seq = 0;
  if (next_page_token) next_page_token->clear();
  while (st.step()) {
    if (int(out.size()) == page_size) {
      if (next_page_token) *next_page_token = std::to_string(last_seq);
      break;
    }
    out.push_back(read_row(&st));
    last_seq = st.i64(kNextColumn);
  }
  for (auto& j : out) {
    load_transitions(j);
    fill_counts(j);
  }
  return out;
}

std::optional<StoredJob> JobStore::claim_next() {
  std::lock_guard lk(mu_);
  Transaction tx(db_);
  // An ensemble's job waits until none of its members is queued or running.
  Stmt st(db_, (std::string("SELECT ") + kColumns +
                " FROM jobs WHERE state = 1 AND NOT EXISTS (SELECT 1 FROM jobs m WHERE m.parent = jobs.id AND m.state IN (1, 2)) "
                "ORDER BY seq LIMIT 1")
                   .c_str());
  if (!st.step()) {
    tx.commit();
    return std::nullopt;
  }
  StoredJob j = read_row(&st);
  const std::string now = utc_now();
  Stmt up(db_, "UPDATE jobs SET state = 2, attempts = attempts + 1, updated = ? WHERE id = ?");
  up.bind(1, now).bind(2, j.job.id()).step();
  j.job.set_attempts(j.job.attempts() + 1);
  add_transition(db_, j.job.id(), v1::RUNNING, now, "started (attempt " + std::to_string(j.job.attempts()) + ")");
  tx.commit();
  j.job.set_state(v1::RUNNING);
  j.job.set_updated_utc(now);
  load_transitions(j);
  return j;
}

void JobStore::transition(const std::string& id, v1::JobState state, const std::string& reason, const std::string& error,
                          std::int64_t result_bytes, bool crashed) {
  std::lock_guard lk(mu_);
  Transaction tx(db_);
  const std::string now = utc_now();
  // Back to the queue from a run: the server ended that attempt cleanly (a stop), so it does not
  // count towards the attempts a crashing job is allowed (requeue_running).
  Stmt up(db_,
          "UPDATE jobs SET state = ?, updated = ?, error = ?, result_bytes = CASE WHEN ? >= 0 THEN ? ELSE result_bytes END, "
          "interrupted = interrupted + CASE WHEN ? = 1 AND state = 2 THEN 1 ELSE 0 END, crashes = crashes + ? WHERE id = ?");
  up.bind(1, std::int64_t(state)).bind(2, now).bind(3, error).bind(4, result_bytes).bind(5, result_bytes)
      .bind(6, std::int64_t(state)).bind(7, std::int64_t(crashed ? 1 : 0)).bind(8, id).step();
  add_transition(db_, id, state, now, reason);
  tx.commit();
}

namespace {
constexpr const char* kCancelledQueued = "cancelled by the client before it started";
constexpr const char* kMemberCancelled = "its ensemble was cancelled by the client before it started";
}  // namespace

std::optional<StoredJob> JobStore::cancel(const std::string& id, const std::string& owner, std::vector<Change>* ended,
                                          const std::function<void(const std::vector<Change>&)>& before_commit) {
  {
    std::lock_guard lk(mu_);
    Transaction tx(db_);
    Stmt st(db_, "SELECT state FROM jobs WHERE id = ? AND owner = ?");
    st.bind(1, id).bind(2, owner);
    if (!st.step()) return std::nullopt;
    const std::string now = utc_now();
    {  // An ensemble's members: the queued ones end now, the running ones are asked to stop.
      std::vector<std::string> queued;
      Stmt ms(db_, "SELECT id FROM jobs WHERE parent = ? AND state = 1");
      ms.bind(1, id);
      while (ms.step()) queued.push_back(ms.text(0));
      for (const auto& m : queued) {
        Stmt(db_, "UPDATE jobs SET state = 5, updated = ? WHERE id = ?").bind(1, now).bind(2, m).step();
        add_transition(db_, m, v1::CANCELLED, now, kMemberCancelled);
        if (ended) ended->push_back({m, v1::CANCELLED, kMemberCancelled});
      }
      Stmt(db_, "UPDATE jobs SET cancel_requested = 1 WHERE parent = ? AND state = 2").bind(1, id).step();
    }
    if (v1::JobState(st.i64(0)) == v1::QUEUED) {
      Stmt up(db_, "UPDATE jobs SET state = 5, updated = ? WHERE id = ?");
      up.bind(1, now).bind(2, id).step();
      add_transition(db_, id, v1::CANCELLED, now, kCancelledQueued);
      if (ended) ended->push_back({id, v1::CANCELLED, kCancelledQueued});
    } else if (v1::JobState(st.i64(0)) == v1::RUNNING) {
      // Kept in the store, so that neither a worker that has just claimed the job nor a restart
      // after a crash loses it.
      Stmt(db_, "UPDATE jobs SET cancel_requested = 1 WHERE id = ?").bind(1, id).step();
    }
    if (before_commit && ended) before_commit(*ended);
    tx.commit();
  }
  return get(id, owner);
}

int JobStore::requeue_running(const std::string& reason, std::vector<Change>* changed) {
  std::lock_guard lk(mu_);
  Transaction tx(db_);
  struct Row {
    std::string id;
    std::int64_t cancel;
  };
  std::vector<Row> rows;
  {
    Stmt st(db_, "SELECT id, cancel_requested FROM jobs WHERE state = 2");
    while (st.step()) rows.push_back({st.text(0), st.i64(1)});
  }
  const std::string now = utc_now();
  int queued = 0;
  for (const auto& r : rows) {
    // The server went down, not the job (jobs run in processes of their own, which died with it):
    // this does not count against the job.
    if (r.cancel) {
      const char* why = "cancelled by the client; the server stopped before the run did";
      Stmt(db_, "UPDATE jobs SET state = 5, updated = ? WHERE id = ?").bind(1, now).bind(2, r.id).step();
      add_transition(db_, r.id, v1::CANCELLED, now, why);
      if (changed) changed->push_back({r.id, v1::CANCELLED, why});
    } else {
      Stmt(db_, "UPDATE jobs SET state = 1, updated = ? WHERE id = ?").bind(1, now).bind(2, r.id).step();
      add_transition(db_, r.id, v1::QUEUED, now, reason);
      if (changed) changed->push_back({r.id, v1::QUEUED, reason});
      ++queued;
    }
  }
  tx.commit();
  return queued;
}

bool JobStore::cancel_requested(const std::string& id) const {
  std::lock_guard lk(mu_);
  Stmt st(db_, "SELECT cancel_requested FROM jobs WHERE id = ?");
  st.bind(1, id);
  return st.step() && st.i64(0) != 0;
}

void JobStore::save_progress(const std::string& id, const v1::Progress& p) {
  std::lock_guard lk(mu_);
  std::string blob;
  p.SerializeToString(&blob);
  Stmt(db_, "UPDATE jobs SET progress = ? WHERE id = ?").blob(1, blob).bind(2, id).step();
}

std::int64_t JobStore::result_bytes_total(const std::string& owner) const {
  std::lock_guard lk(mu_);
  Stmt st(db_,
          "SELECT COALESCE(SUM(b), 0) FROM (SELECT MAX(result_bytes) AS b FROM jobs WHERE owner = ? AND state = 3 "
          "AND results_removed = 0 GROUP BY hash)");
  st.bind(1, owner);
  st.step();
  return st.i64(0);
}

std::vector<JobStore::Finished> JobStore::finished_results() const {
  std::lock_guard lk(mu_);
  Stmt st(db_,
          "SELECT hash, MAX(updated), MAX(result_bytes) FROM jobs WHERE state = 3 AND results_removed = 0 "
          "AND hash NOT IN (SELECT m.hash FROM jobs m JOIN jobs p ON p.id = m.parent WHERE p.state IN (1, 2)) "
          "GROUP BY hash ORDER BY MAX(updated)");
  std::vector<Finished> out;
  while (st.step()) out.push_back({st.text(0), st.text(1), st.i64(2)});
  return out;
}

void JobStore::mark_results_removed(const std::string& hash, const std::string& reason) {
  std::lock_guard lk(mu_);
  Transaction tx(db_);
  std::vector<std::string> ids;
  {
    Stmt st(db_, "SELECT id FROM jobs WHERE hash = ? AND state = 3 AND results_removed = 0");
    st.bind(1, hash);
    while (st.step()) ids.push_back(st.text(0));
  }
  const std::string now = utc_now();
  for (const auto& id : ids) {
    Stmt(db_, "UPDATE jobs SET results_removed = 1, result_bytes = 0, updated = ? WHERE id = ?").bind(1, now).bind(2, id).step();
    add_transition(db_, id, v1::SUCCEEDED, now, reason);
  }
  tx.commit();
}

bool JobStore::has_hash(const std::string& hash) const {
  std::lock_guard lk(mu_);
  Stmt st(db_, "SELECT 1 FROM jobs WHERE hash = ? LIMIT 1");
  st.bind(1, hash);
  return st.step();
}

std::vector<StoredJob> JobStore::active_jobs() const {
  std::lock_guard lk(mu_);
  Stmt st(db_, (std::string("SELECT ") + kColumns + " FROM jobs WHERE state IN (1, 2) ORDER BY seq").c_str());
  std::vector<StoredJob> out;
  while (st.step()) out.push_back(read_row(&st));
  return out;
}

std::int64_t JobStore::job_count() const {
  std::lock_guard lk(mu_);
  Stmt st(db_, "SELECT COUNT(*) FROM jobs");
  st.step();
  return st.i64(0);
}

void JobStore::insert_recovered(const StoredJob& j) {
  std::lock_guard lk(mu_);
  Transaction tx(db_);
  std::string blob;
  j.scenario.SerializeToString(&blob);
  Stmt ins(db_,
           "INSERT INTO jobs(id, owner, name, hash, request_id, state, created, updated, error, attempts, scenario, "
           "result_bytes, results_removed, crashes, parent, member) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  ins.bind(1, j.job.id()).bind(2, j.owner).bind(3, j.job.name()).bind(4, j.job.scenario_hash());
  if (j.job.request_id().empty())
    ins.null(5);
  else
    ins.bind(5, j.job.request_id());
  ins.bind(6, std::int64_t(j.job.state())).bind(7, j.job.created_utc()).bind(8, j.job.updated_utc()).bind(9, j.job.error())
      .bind(10, std::int64_t(j.job.attempts())).blob(11, blob).bind(12, j.job.result_bytes())
      .bind(13, std::int64_t(j.results_removed ? 1 : 0)).bind(14, std::int64_t(j.crashes)).bind(15, j.job.parent_id())
      .bind(16, std::int64_t(j.job.parent_id().empty() ? -1 : j.job.member_index()));
  ins.step();
  for (const auto& t : j.job.transitions()) add_transition(db_, j.job.id(), t.state(), t.time_utc(), t.reason());
  for (const auto& [rid, digest] : j.more_requests)
    Stmt(db_, "INSERT OR IGNORE INTO requests(owner, request_id, job, request_hash) VALUES (?, ?, ?, ?)")
        .bind(1, j.owner).bind(2, rid).bind(3, j.job.id()).bind(4, digest).step();
  tx.commit();
}

std::optional<std::pair<StoredJob, std::string>> JobStore::find_request(const std::string& owner,
                                                                       const std::string& request_id) const {
  std::lock_guard lk(mu_);
  // The digest of the request: the job's own where the id created it, else the one recorded with the id.
  Stmt st(db_, (std::string("SELECT ") + kColumns +
                ", CASE WHEN request_id IS ?2 THEN COALESCE(request_hash, '') "
                "ELSE (SELECT request_hash FROM requests WHERE owner = ?1 AND request_id = ?2) END" + kNamedByRequest)
                   .c_str());
  st.bind(1, owner).bind(2, request_id);
  if (!st.step()) return std::nullopt;
  std::pair<StoredJob, std::string> out{read_row(&st), st.text(kNextColumn)};
  load_transitions(out.first);
  return out;
}

}  // namespace runout::jobs
