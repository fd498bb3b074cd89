#pragma once
// `runout run` on an ensemble (a scenario with `variations`): the members through the embedded job
// system in a local state directory, then the aggregate into the output.
#include <functional>
#include <string>

#include "jobs/scenario/scenario.hpp"
#include "runout/v1/service.pb.h"

namespace runout::cli {

struct EnsembleRun {
  std::string out_dir;    ///< the staged output folder (exists, empty)
  std::string state_dir;  ///< empty: default_state_dir()
  int workers = 0;        ///< cores to use; 0: all
  bool quiet = false, tty = false;
  bool with_members = false;  ///< also copy each member's results into out_dir/members/member_<k>
  bool terrain_cache = true;  ///< members share prepared grids (the state directory's cache/terrain)
  std::function<bool()> interrupted;  ///< Ctrl-C or SIGTERM arrived
};

struct RunSummaryOut {
  int members = 0;
  double seconds = 0;
  std::string state_dir, job;
};

/// "[########............]  42 of 100 members done, 2 running, 56 queued" (the bar with `bar`).
std::string ensemble_progress(const v1::EnsembleCounts& c, bool bar);

/// $RUNOUT_STATE_DIR, else $XDG_CACHE_HOME/runout, else ~/.cache/runout.
std::string default_state_dir();

/// Runs the ensemble; returns the exit code (kOk, or a failure with its message on standard error).
int run_ensemble(const jobs::ResolvedScenario& r, const EnsembleRun& a, RunSummaryOut& summary);

}  // namespace runout::cli
