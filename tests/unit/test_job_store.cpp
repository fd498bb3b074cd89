// The job store on its own: this program links only the job system's library (runout_jobs), which
// is what shows that the job system needs neither the numerics nor the drawing (ctest
// arch.job_system_links checks its shared libraries).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "jobs/system/store.hpp"
#include "tests/support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace runout;
using runout::jobs::JobStore;

namespace {

v1::Scenario named(const std::string& name) {
  v1::Scenario s;
  s.set_name(name);
  return s;
}

}  // namespace

TEST(JobStore, SubmitClaimFinishInOrder) {
  test_support::TempDir dir;
  JobStore st(dir / "jobs.db");
  const auto a = st.submit("alice", "hash-a", "req-1", named("a"), 10);
  const auto b = st.submit("alice", "hash-b", "req-2", named("b"), 10);
  ASSERT_TRUE(a.created);
  ASSERT_TRUE(b.created);
  EXPECT_EQ(a.job.job.state(), v1::QUEUED);

  const auto first = st.claim_next();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->job.id(), a.job.job.id());  // oldest first
  EXPECT_EQ(first->job.state(), v1::RUNNING);
  EXPECT_EQ(first->job.attempts(), 1);

  st.transition(first->job.id(), v1::SUCCEEDED, "done", "", 1234);
  const auto done = st.get(first->job.id());
  ASSERT_TRUE(done);
  EXPECT_EQ(done->job.state(), v1::SUCCEEDED);
  EXPECT_TRUE(jobs::is_final(done->job.state()));
  EXPECT_EQ(st.job_count(), 2);
}

TEST(JobStore, RetryWithTheSameRequestIdIsAnsweredByTheSameJob) {
  test_support::TempDir dir;
  JobStore st(dir / "jobs.db");
  const auto a = st.submit("alice", "hash-a", "req-1", named("a"), 10, "digest-1");
  const auto again = st.submit("alice", "hash-a", "req-1", named("a"), 10, "digest-1");
  EXPECT_FALSE(again.created);
  EXPECT_EQ(again.job.job.id(), a.job.job.id());
  const auto found = st.find_request("alice", "req-1");
  ASSERT_TRUE(found);
  EXPECT_EQ(found->second, "digest-1");
  EXPECT_THROW(st.submit("alice", "hash-other", "req-1", named("x"), 10), jobs::RequestIdConflict);
  EXPECT_FALSE(st.get(a.job.job.id(), "bob"));  // another owner does not see it
}

TEST(JobStore, QueueLimitPerOwner) {
  test_support::TempDir dir;
  JobStore st(dir / "jobs.db");
  st.submit("alice", "h1", "r1", named("1"), 2);
  st.submit("alice", "h2", "r2", named("2"), 2);
  EXPECT_THROW(st.submit("alice", "h3", "r3", named("3"), 2), jobs::QueueFull);
  EXPECT_NO_THROW(st.submit("bob", "h3", "r3", named("3"), 2));
}

TEST(JobStore, RunningJobsAreQueuedAgainAfterARestartWithoutCountingACrash) {
  test_support::TempDir dir;
  const auto db = dir / "jobs.db";
  std::string id;
  {
    JobStore st(db);
    id = st.submit("alice", "h1", "r1", named("1"), 10).job.job.id();
    ASSERT_TRUE(st.claim_next());
  }
  JobStore st(db);  // the server came back
  std::vector<JobStore::Change> changed;
  EXPECT_EQ(st.requeue_running("the server restarted", &changed), 1);
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_EQ(changed[0].id, id);
  const auto j = st.get(id);
  ASSERT_TRUE(j);
  EXPECT_EQ(j->job.state(), v1::QUEUED);
  EXPECT_EQ(j->crashes, 0);
}

// Cancelling an ensemble ends its queued members with it, and says which jobs it ended (the server
// writes each one's log line, which `runout serve --recover` reads); a running member is asked to
// stop instead, and its worker ends it.
TEST(JobStore, CancellingAnEnsembleEndsItsQueuedMembersAndNamesThem) {
  test_support::TempDir dir;
  JobStore st(dir / "jobs.db");
  std::vector<JobStore::NewMember> members;
  for (int k = 0; k < 3; ++k) members.push_back({k, "member-hash-" + std::to_string(k), named("m" + std::to_string(k))});
  const auto e = st.submit_ensemble("alice", "ensemble-hash", "req-e", named("e"), members, 10);
  ASSERT_TRUE(e.created);
  const auto running = st.claim_next();  // the first member
  ASSERT_TRUE(running);
  std::vector<JobStore::Change> ended;
  const auto parent = st.cancel(e.job.job.id(), "alice", &ended);
  ASSERT_TRUE(parent);
  EXPECT_EQ(parent->job.state(), v1::CANCELLED);
  ASSERT_EQ(ended.size(), 3u);  // the two queued members and the ensemble itself
  const auto listed = st.members(e.job.job.id());
  ASSERT_EQ(listed.size(), 3u);
  EXPECT_EQ(listed[0].job.id(), running->job.id());
  EXPECT_EQ(listed[0].job.state(), v1::RUNNING);
  EXPECT_TRUE(st.cancel_requested(running->job.id()));
  for (int k = 1; k < 3; ++k) {
    EXPECT_EQ(listed[std::size_t(k)].job.state(), v1::CANCELLED);
    EXPECT_EQ(ended[std::size_t(k) - 1].id, listed[std::size_t(k)].job.id());
    EXPECT_EQ(ended[std::size_t(k) - 1].state, v1::CANCELLED);
    EXPECT_NE(ended[std::size_t(k) - 1].reason.find("ensemble was cancelled"), std::string::npos);
  }
  EXPECT_EQ(ended[2].id, e.job.job.id());
  std::vector<JobStore::Change> again;
  st.cancel(e.job.job.id(), "alice", &again);
  EXPECT_TRUE(again.empty());  // nothing left to end
}
