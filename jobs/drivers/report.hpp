#pragma once
// `runout report`: a finished run's folder as one PDF for a hazard report (figures/report.hpp), read
// back from what the run wrote (run.json, the hazard rasters, elevation.tif, release.tif,
// path_profile.csv): the parameters in words, the mass balance, the results, the points of interest
// and the zones as tables, the maps at a stated scale (the pressure map with the zones' boundaries,
// drawn by the run's zones and rule) and the path profile.
#include <string>

#include "jobs/drivers/run.hpp"
#include "jobs/formats/run_record.hpp"
#include "jobs/figures/report.hpp"

namespace runout::jobs {

struct ReportOptions {
  std::string paper = "a4";  ///< a4 or a3 (landscape)
  double dpi = 300;          ///< the maps' rasters
};

/// The scenario's outputs.report at the end of a run: `run_dir`/report.pdf on `paper`, written
/// beside and moved into place. Returns false, with a note in `sum.notes` and no file, when the
/// report cannot be made: the run's results stand without it.
bool write_report_output(const std::string& run_dir, const std::string& paper, RunSummary& sum);

/// The report's tables from a run's record: the points of interest, the pressure zones and, where
/// the run has structures, the structures (the flow next to each; a 3D run's or a nest's loads with
/// their verdict).
std::vector<figures::ReportTable> report_tables(const v1::RunRecord& rec);

/// Write the report of the run in `run_dir` to `pdf_path`. Throws std::runtime_error naming the file
/// that is missing or unreadable (a laboratory run has no maps on terrain: refused).
figures::ReportLayout write_run_report(const std::string& run_dir, const std::string& pdf_path, const ReportOptions& opt);

}  // namespace runout::jobs
