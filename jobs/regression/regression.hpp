#pragma once
// The nightly regression (validation.md C1): figures of a finished In den Arelen run compared with
// the last accepted reference (regression/in-den-arelen/reference.json and its max_depth.tif), a
// Markdown report with the map and a difference map, and the promotion of a run to the reference.
// Works on result folders; getting the run done (through the service) is the caller's business.
#include <cmath>
#include <string>
#include <vector>

namespace runout::jobs {

/// What is compared. Distances in metres, areas in m2, depth in m, speed in m/s.
struct RegressionFigures {
  double runout_m = 0;             ///< from the release centroid (run.json results)
  double affected_area_m2 = 0;     ///< max depth above the outline threshold
  double max_depth_m = 0;
  double max_speed_m_s = 0;
  double volume_error = 0;         ///< relative mass-balance error
  double farmhouse_depth_m = 0;    ///< maximum depth at the farmhouse (46.8367 N, 9.8539 E)
  double farmhouse_distance_m = 0; ///< from the farmhouse to the nearest cell with max depth >= 0.1 m (0: reached)
  /// The runout along the path and its angle (run.json results.path; reported, not compared: the
  /// references predate it). NaN without one.
  double path_runout_m = NAN, path_alpha_deg = NAN;
  std::string path_criterion;
};

/// Tolerances: relative for the first four, absolute for the rest.
struct RegressionTolerances {
  double runout_rel = 0.02, area_rel = 0.03, max_depth_rel = 0.05, max_speed_rel = 0.05;
  double volume_error_abs = 1e-12;  ///< upper bound, not a difference
  double farmhouse_distance_abs = 30;  ///< may grow by at most this much
  double depth_map_abs = 0.5;       ///< largest allowed |difference| of the max-depth maps, where either exceeds 0.1 m
};

struct RegressionReference {
  RegressionFigures figures;
  RegressionTolerances tolerances;
  std::string accepted_utc, reason, software_version, scenario_hash;
};

struct RegressionRow {
  std::string name, unit;
  double reference = 0, value = 0, difference = 0, tolerance = 0;
  bool ok = true;
};

struct RegressionOutcome {
  std::vector<RegressionRow> rows;
  bool ok = true;
  std::string note;       ///< e.g. why the depth maps could not be compared
  std::string path_note;  ///< the runout along the path, reported
};

/// Figures of a result folder (run.json, max_depth.tif). Throws std::runtime_error. A farmhouse
/// outside the run's grid is an error unless `farmhouse_optional` (its figures are then NaN).
RegressionFigures measure_run(const std::string& results_dir, bool farmhouse_optional = false);
/// Read reference.json of a reference folder. Throws std::runtime_error when absent or unreadable.
RegressionReference read_reference(const std::string& reference_dir);
/// Compare a run with the reference; writes diff.tif and diff.png (run minus reference max depth)
/// into `out_dir` when the grids agree.
RegressionOutcome compare_run(const RegressionFigures& run, const RegressionReference& ref, const std::string& run_max_depth,
                              const std::string& reference_dir, const std::string& out_dir);
/// report.md in `out_dir`.
void write_report(const std::string& out_dir, const RegressionOutcome& o, const RegressionReference& ref,
                  const std::string& job_id, const std::string& scenario_hash, double wall_s);
/// Make a run the reference: reference.json (tolerances kept from the old reference when there is
/// one), max_depth.tif, and a line in HISTORY.md with the reason.
void accept_reference(const std::string& reference_dir, const RegressionFigures& f, const std::string& run_max_depth,
                      const std::string& reason, const std::string& scenario_hash, const std::string& version);

}  // namespace runout::jobs
