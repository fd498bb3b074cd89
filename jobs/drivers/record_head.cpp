#include "jobs/drivers/record_head.hpp"

#include "jobs/digest/sha256.hpp"

#include <omp.h>

#include <cstdlib>
#include <ctime>

namespace runout::jobs {

v1::RunRecord run_record_head(const ResolvedScenario& s, const std::string& engine) {
  v1::RunRecord rec;
  *rec.mutable_software() = this_software();
  rec.set_engine(engine);
  char b[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  rec.set_created_utc(b);
  rec.set_scenario_file(s.source);
  *rec.mutable_scenario() = s.scenario;
  for (const auto& path : s.input_files) {
    auto* in = rec.add_inputs();
    in->set_path(path);
    in->set_sha256(sha256_file(path));
  }
  auto* ex = rec.mutable_execution();
  ex->set_threads(omp_get_max_threads());
  const char* env = std::getenv("PETSC_OPTIONS");
  ex->set_petsc_options_env(env ? env : "");
  return rec;
}

}  // namespace runout::jobs
