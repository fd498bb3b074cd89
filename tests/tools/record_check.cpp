// record_check RUN_JSON [FIGURE...]: reads run.json as runout.v1.RunRecord (the typed record, never
// as text) and prints its engine, the grid's CRS and each named figure (jobs::figure_by_name). Exits
// 1 when the file is not a run record or a named figure is missing or not finite, 2 on a bad
// command line. The command-line tests check a run's record with it.
#include <cmath>
#include <cstdio>
#include <string>

#include "jobs/formats/run_record.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: record_check RUN_JSON [FIGURE...]\n");
    return 2;
  }
  try {
    const runout::v1::RunRecord rec = runout::jobs::read_run_record(argv[1]);
    std::printf("engine = %s\n", rec.engine().c_str());
    if (rec.has_grid()) std::printf("grid.crs = %s\n", rec.grid().crs().c_str());
    int missing = 0;
    for (int k = 2; k < argc; ++k) {
      const double v = runout::jobs::figure_by_name(rec, argv[k]);
      std::printf("%s = %.10g\n", argv[k], v);
      if (!std::isfinite(v)) {
        std::fprintf(stderr, "record_check: %s: no finite figure '%s'\n", argv[1], argv[k]);
        ++missing;
      }
    }
    return missing == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "record_check: %s\n", e.what());
    return 1;
  }
}
