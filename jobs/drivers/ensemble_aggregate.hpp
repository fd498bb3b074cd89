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
// A zoning (scenario zoning) is an ensemble of one member per return period whose aggregate is the
// zones (jobs/drivers/zoning.hpp).
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

/// The finest member's grid: every member's rasters lie on it or are resampled onto it.
terrain::Grid aggregate_grid(const ResolvedScenario& e, const std::vector<MemberResults>& members);
/// A member's record; throws std::runtime_error naming the member where it cannot be read.
v1::RunRecord member_record(const MemberResults& m);
/// A member's figures into the record (members[]), and which points of interest it reached.
void record_member(const MemberResults& m, const v1::RunRecord& r, v1::EnsembleRecord& rec, std::vector<int>& reached);
/// The record's head: software, kind ("ensemble" or "zoning"), scenario, design, creation time.
v1::EnsembleRecord record_head(const ResolvedScenario& e);

/// Aggregate the members into `out_dir` (existing, empty); a zoning's (scenario zoning) are its
/// zones (jobs/drivers/zoning.hpp). `progress(done, total)` after each member
/// read; returning false throws AggregateStopped (the caller discards the folder). Throws
/// terrain::TerrainError or std::runtime_error naming the member whose results cannot be read.
v1::EnsembleRecord aggregate_ensemble(const ResolvedScenario& ensemble, const std::vector<MemberResults>& members,
                                      const std::string& out_dir, const std::function<bool(int, int)>& progress = {});

}  // namespace runout::jobs
