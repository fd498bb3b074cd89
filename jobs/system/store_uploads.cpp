// The job store's records of uploads: per client, for the upload quota and their collection.
#include <ctime>

#include "jobs/system/store.hpp"
#include "jobs/system/store_sql.hpp"

namespace runout::jobs {

using sql::Stmt;

void JobStore::record_upload(const std::string& owner, const std::string& id, std::int64_t bytes) {
  std::lock_guard lk(mu_);
  Stmt(db_, "INSERT OR REPLACE INTO uploads(id, owner, bytes, time) VALUES (?, ?, ?, ?)")
      .bind(1, id)
      .bind(2, owner)
      .bind(3, bytes)
      .bind(4, std::int64_t(std::time(nullptr)))
      .step();
}

std::int64_t JobStore::upload_bytes(const std::string& owner) const {
  std::lock_guard lk(mu_);
  Stmt st(db_, "SELECT COALESCE(SUM(bytes), 0) FROM uploads WHERE owner = ?");
  st.bind(1, owner);
  st.step();
  return st.i64(0);
}

std::vector<std::string> JobStore::uploads_older_than(double cutoff_epoch_s) const {
  std::lock_guard lk(mu_);
  Stmt st(db_, "SELECT id FROM uploads GROUP BY id HAVING MAX(time) < ?");
  st.bind(1, std::int64_t(cutoff_epoch_s));
  std::vector<std::string> out;
  while (st.step()) out.push_back(st.text(0));
  return out;
}

bool JobStore::forget_upload(const std::string& id, const std::string& owner) {
  std::lock_guard lk(mu_);
  Stmt(db_, "DELETE FROM uploads WHERE id = ? AND owner = ?").bind(1, id).bind(2, owner).step();
  Stmt st(db_, "SELECT COUNT(*) FROM uploads WHERE id = ?");
  st.bind(1, id);
  st.step();
  return st.i64(0) > 0;
}

void JobStore::forget_upload(const std::string& id) {
  std::lock_guard lk(mu_);
  Stmt(db_, "DELETE FROM uploads WHERE id = ?").bind(1, id).step();
}

}  // namespace runout::jobs
