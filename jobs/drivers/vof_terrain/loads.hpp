#pragma once
// The flow's load on each structure of a 3D run on the DEM (scenario structures[]): after every step
// the pressure's force on the structure's patch (engine/vof/loads.hpp) in the grid's CRS (east,
// north, up); its peak (the largest horizontal force), the impulse (the horizontal force integrated
// over the steps), the highest face pressure and, at the peak force, the flow's profile in the column
// in front of the face that took the highest pressure. Series every `interval` seconds go to
// structure_loads.csv. The figures and series travel with a checkpoint.
#include <string>
#include <vector>

#include "engine/vof/backend.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_terrain/hazard.hpp"
#include "jobs/drivers/vof_terrain/setup.hpp"
#include "jobs/formats/checkpoint.hpp"

namespace runout::jobs::vof_terrain {

/// Whether the loads of a structure in a flow `depth_m` deep next to it resolve the impact on
/// columns `column_width_m` wide: at most a quarter of the depth (the wall-impact verification holds
/// its force to 15 % with four cells over the flow's depth, and the farmhouse's loads grow as the
/// columns shrink where they are wider: validation.md D4). Sets q.loads_resolved and q.loads_note.
void loads_verdict(double column_width_m, StructureSummary& q);

class StructureLoads {
 public:
  StructureLoads(const TerrainSetup& su, double interval);
  bool empty() const { return loads_.empty(); }
  /// After a step of length dt ending at t.
  void update(double t, double dt, const engine::vof::VofBackend& s, const ColumnHazard& hazard);
  void save(VofCheckpoint& cp) const;
  /// Throws ScenarioError naming `path` when the checkpoint lacks a structure's figures.
  void restore(const VofCheckpoint& cp, const std::string& path);
  /// The figures into the summaries (matched by name, their max_depth_next_m set), with the verdict
  /// of loads_verdict on each.
  void summarise(std::vector<StructureSummary>& out) const;
  /// structure_loads.csv: time_s, structure, force_east_kn, force_north_kn, force_up_kn,
  /// force_horizontal_kn, max_pressure_kpa. Returns the file's name.
  std::string write_csv(const std::string& out_dir) const;
  /// structure_loads.png and .pdf: the horizontal force and the highest pressure over time, titled
  /// with `title`. Returns the files' names (none when no structure has two samples).
  std::vector<std::string> write_plot(const std::string& out_dir, const std::string& title) const;

 private:
  struct Load {
    std::string name, patch;
    double peak = 0, peak_t = 0, peak_e = 0, peak_n = 0, peak_u = 0, impulse = 0, last_h = 0;
    double p_max = 0, p_max_t = 0, p_max_height = 0, area = 0;
    int p_max_face = -1;
    std::vector<double> t, east, north, up, p;  // the series (kN, kPa)
    std::vector<double> front_h, front_a, front_s;
  };
  const TerrainSetup& su_;
  double interval_, next_ = 0;
  std::vector<int> column_of_, layer_of_;  // per cell
  std::vector<Load> loads_;
};

}  // namespace runout::jobs::vof_terrain
