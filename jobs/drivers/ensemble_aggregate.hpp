#pragma once
// The aggregate of an ensemble (docs/user/ensembles.md): once every member has run, its hazard rasters
// and run records are read and turned into
//   - probability_<quantity>_<threshold>.tif: per cell the fraction of members whose maximum reaches
//     the threshold (0-1, COG, QGIS style beside it), with a map of each;
//   - <quantity>_p<percentile>.tif: the members' percentiles of max depth, speed and pressure;
//   - runout_distribution.csv and runout_histogram.png/.pdf: the runout along the path per member;
//   - the probability of reaching each point of interest (run.json, and on the maps);
//   - run.json: the ensemble's record (runout.v1.EnsembleRecord).
// A member at another resolution is resampled onto the finest member's grid (nearest neighbour).
#include <functional>
#include <string>
#include <vector>

#include "jobs/ensemble/variations.hpp"
#include "jobs/scenario/scenario.hpp"
#include "runout/v1/run_record.pb.h"

namespace runout::jobs {

/// One member's results: its place and values, its scenario hash and its result directory.
struct MemberResults {
  ensemble::Member member;
  std::string hash;
  std::string dir;
};

/// Thrown when the progress hook asks the aggregate to stop.
struct AggregateStopped {};

/// Aggregate the members into `out_dir` (existing, empty). `progress(done, total)` after each member
/// read; returning false throws AggregateStopped (the caller discards the folder). Throws
/// terrain::TerrainError or std::runtime_error naming the member whose results cannot be read.
v1::EnsembleRecord aggregate_ensemble(const ResolvedScenario& ensemble, const std::vector<MemberResults>& members,
                                      const std::string& out_dir, const std::function<bool(int, int)>& progress = {});

}  // namespace runout::jobs
