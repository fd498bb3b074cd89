#include "jobs/drivers/nest/run.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>

namespace runout::jobs::nest {

NestSummary run_nest(const ResolvedScenario& parent, const NestBoundary& b, engine::HazardMaps& hz, const std::string& dir,
                     const RunOptions& opt, bool release_inside) {
  ResolvedScenario r = *parent.nest;  // to the scenario's end or its own stop rule; nothing enters after the record's end
  double deepest = b.max_depth();
  for (std::size_t k = 0; k < b.cells().size(); ++k)
    if (b.cells()[k]) deepest = std::max(deepest, hz.max_depth[k]);
  if (!(deepest > 0)) deepest = 1.0;  // nothing reached the nest: any layers do
  auto* me = r.scenario.mutable_mesh();
  if (!parent.scenario.nest().has_first_layer_m()) me->set_first_layer_m(deepest / 5);
  if (!parent.scenario.nest().has_band_height_m()) me->set_band_height_m(8 * deepest);
  NestLink link;
  link.boundary = &b;
  link.start_time = release_inside ? 0.0 : std::max(0.0, b.first_inflow_time() - 1.0);
  RunOptions o;
  o.progress = opt.progress;
  o.progress_every = opt.progress_every;
  o.terrain_cache_dir = opt.terrain_cache_dir;
  o.nest = &link;
  // A nested run's checkpoint is its 3D run's: the depth-averaged part runs again from its start
  // (it is deterministic and takes seconds) and hands the 3D run the same record.
  o.checkpoint_path = opt.checkpoint_path;
  o.checkpoint_interval_s = opt.checkpoint_interval_s;
  o.restart_path = opt.restart_path;
  std::filesystem::create_directories(dir);
  const auto t0 = std::chrono::steady_clock::now();
  RunSummary inner = run_scenario(r, dir, o);
  NestSummary s;
  s.cancelled = inner.stop == "cancelled";
  s.continued_from = link.continued_from;  // NaN unless it continued from a checkpoint
  s.structures = std::move(inner.structures);
  s.seconds_3d = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.cells = b.cell_count();
  s.boundary_faces = int(b.faces().size());
  s.recorded_steps = b.steps();
  s.mesh_cells = link.mesh_cells;
  s.column_width_m = link.column_width_m;
  s.first_layer_m = link.first_layer_m;
  s.band_height_m = link.band_height_m;
  s.inflow_depth_averaged_m3 = b.inflow_volume();
  s.inflow_3d_m3 = link.inflow_m3;
  s.volume_error_3d = link.volume_error;
  s.start_time_s = link.start_time;
  for (std::size_t k = 0; k < b.cells().size() && !s.cancelled; ++k) {
    if (!b.cells()[k] || link.maps.max_depth.empty()) continue;
    hz.max_depth[k] = link.maps.max_depth[k];
    hz.max_speed[k] = link.maps.max_speed[k];
    hz.max_pressure[k] = link.maps.max_pressure[k];
    hz.arrival_time[k] = link.maps.arrival_time[k];
    if (!hz.final_depth.empty() && !link.maps.final_depth.empty()) hz.final_depth[k] = link.maps.final_depth[k];
  }
  return s;
}

}  // namespace runout::jobs::nest
