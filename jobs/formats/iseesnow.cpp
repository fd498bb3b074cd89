#include "jobs/formats/iseesnow.hpp"

#include <cctype>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "jobs/formats/run_record.hpp"

namespace runout::jobs {
namespace fs = std::filesystem;

std::vector<std::string> write_iseesnow(const ResolvedScenario& s, const std::string& simulation_id, const std::string& out_dir,
                                        const terrain::Grid& grid, const engine::Sh2dResult& res, double cpu_seconds) {
  const auto& d = res.diag;
  const auto& hz = res.hazard;
  auto out = [&](const std::string& name) { return (fs::path(out_dir) / name).string(); };
  auto masked = [&](const std::vector<double>& v) { return terrain::masked_outside(grid, v); };
  const std::string stem = fs::path(s.releases.front().path).stem().string() + "_" + simulation_id + "_null_runout";
  terrain::write_ascii_on(out(stem + "_pft.asc"), s.dem.dem_path, grid, masked(hz.max_depth));
  terrain::write_ascii_on(out(stem + "_pfv.asc"), s.dem.dem_path, grid, masked(hz.max_speed));
  // The benchmark's result table (simulationResultTable.csv): one row per simulation; the
  // leading digits of the id are the row index, the rest the test case.
  std::size_t digits = 0;
  while (digits < simulation_id.size() && std::isdigit(static_cast<unsigned char>(simulation_id[digits]))) ++digits;
  const std::string index = digits ? std::to_string(std::stoi(simulation_id.substr(0, digits))) : "";
  std::ofstream csv(out("iseesnow_" + simulation_id + ".csv"));
  csv << ",testCase,computation duration (CPU) [s],avalanche flow time [s],volume at t0 [m3],"
         "volume at tFinal [m3],spatial resolution x [m],spatial resolution y [m],number of particles\n";
  csv << index << "," << simulation_id.substr(digits) << "," << json_number(cpu_seconds) << "," << json_number(d.t) << ","
      << json_number(d.volume_initial) << "," << json_number(d.volume_final) << "," << json_number(grid.dx) << "," << json_number(grid.dx) << ",\n";
  if (!csv) throw std::runtime_error("writing the ISeeSnow CSV failed");
  // The model configuration file the benchmark asks for, named like the peak fields.
  std::ofstream cfg(out(stem + ".txt"));
  const auto& m = s.scenario.material();
  cfg << "runout " << this_software().version() << ": depth-averaged Savage-Hutter model (NOC-TVD scheme, "
      << "curvature in the bed friction " << (s.scenario.numerics().curvature_off() ? "off" : "on") << ")\n"
      << "scenario = " << s.scenario.name() << "\n"
      << "rheology = " << (m.rheology().empty() ? "coulomb" : m.rheology()) << "\n";
  if (m.has_voellmy_mu()) cfg << "mu = " << json_number(m.voellmy_mu()) << "\n";
  if (m.has_voellmy_xi()) cfg << "xi_m_s2 = " << json_number(m.voellmy_xi()) << "\n";
  if (m.has_bed_friction_deg()) cfg << "bed_friction_deg = " << json_number(m.bed_friction_deg()) << "\n";
  if (m.has_internal_friction_deg()) cfg << "internal_friction_deg = " << json_number(m.internal_friction_deg()) << "\n";
  cfg << "earth_pressure = " << (m.earth_pressure().empty() ? "unity" : m.earth_pressure()) << "\n"
      << "limiter = " << (s.scenario.numerics().limiter().empty() ? "minmod" : s.scenario.numerics().limiter()) << "\n"
      << "cfl = " << json_number(s.config.time.cfl) << "\n"
      << "cell_size_m = " << json_number(grid.dx) << "\n"
      << "release_volume_m3 = " << json_number(d.volume_initial) << "\n"
      << "stop = " << engine::to_string(d.stop) << " at t = " << json_number(d.t) << " s\n";
  if (!cfg) throw std::runtime_error("writing the ISeeSnow configuration file failed");
  return {stem + ".txt", stem + "_pft.asc", stem + "_pfv.asc", "iseesnow_" + simulation_id + ".csv"};
}

}  // namespace runout::jobs
