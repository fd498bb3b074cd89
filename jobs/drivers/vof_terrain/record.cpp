#include "jobs/drivers/vof_terrain/record.hpp"

#include <cmath>

#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/record_head.hpp"
#include "jobs/drivers/vof_support.hpp"
#include "jobs/formats/run_record.hpp"

namespace runout::jobs::vof_terrain {

namespace {

void write_grid(const TerrainSetup& su, v1::RunRecord& rec) {
  record_inputs(rec, su.dem, su.grid, su.release);
  auto* gr = rec.mutable_grid();
  gr->add_local_origin(su.frame.x);  // the engine's frame: x east, y up from origin[2], z south
  gr->add_local_origin(su.frame.y);
  gr->add_local_origin(su.frame.z);
  auto* tm = rec.mutable_terrain_mesh();
  tm->set_columns(su.columns_mesh.kept_columns());
  tm->set_layers(su.columns.layers);
  tm->set_cells(su.mesh.cells());
  tm->set_first_layer_m(su.columns.levels[1]);
  tm->set_growth(su.spec.growth);
  tm->set_band_height_m(su.columns.levels.back());
  tm->set_refinement(su.columns.refinement);
  tm->set_column_width_m(su.columns_mesh.dx);
  tm->set_refinement_reason(su.refinement_reason);
  const auto& q = su.quality;
  tm->set_non_orthogonality_max_deg(q.non_orthogonality_max_deg);
  tm->set_non_orthogonality_mean_deg(q.non_orthogonality_mean_deg);
  tm->set_skewness_max(q.skewness_max);
  tm->set_skewness_mean(q.skewness_mean);
  tm->set_aspect_ratio_max(q.aspect_ratio_max);
  tm->set_aspect_ratio_mean(q.aspect_ratio_mean);
  const auto& c = su.corridor;
  tm->set_corridor(c.kind);
  tm->set_domain_columns(su.domain_columns);
  if (c.kind == "footprint") {
    tm->set_corridor_margin_m(c.margin_m);
    tm->set_footprint_columns(c.footprint_cells);
    tm->set_footprint_seconds(c.footprint_seconds);
  }
  if (c.kind == "polygon") tm->set_corridor_path(c.path);
}

void write_profiles(const TerrainRunFacts& f, v1::RunRecord& rec) {
  const auto& su = f.su;
  const auto& hz = f.hazard.maps();
  for (std::size_t n = 0; n < su.points.size(); ++n) {
    const auto& p = su.points[n];
    auto* pp = rec.add_profiles();
    pp->set_name(p.name);
    pp->set_x(p.at.x);
    pp->set_y(p.at.y);
    pp->set_ground_m(su.grid.z[p.column]);
    if (!std::isnan(hz.arrival_time[p.column])) pp->set_arrival_time_s(hz.arrival_time[p.column]);
    pp->set_max_depth_m(hz.max_depth[p.column]);
    pp->set_max_depth_time_s(f.hazard.deepest_time(n));
    pp->set_max_depth_averaged_speed_m_s(hz.max_speed[p.column]);
    const Profile& pr = f.hazard.deepest_profile(n);
    for (std::size_t j = 0; j < pr.height.size(); ++j) *pp->add_profile_height_alpha_speed() = profile_point(pr.height[j], pr.alpha[j], pr.speed[j]);
  }
}

}  // namespace

void write_terrain_record(const std::string& path, const ResolvedScenario& r, const TerrainRunFacts& f) {
  const auto& su = f.su;
  const auto& sum = f.sum;
  v1::RunRecord rec = run_record_head(r, "vof");
  write_grid(su, rec);
  rec.mutable_terrain_mesh()->set_corridor_outflow_m3(f.corridor_outflow);
  rec.mutable_terrain_mesh()->set_domain_edge_outflow_m3(f.domain_edge_outflow);
  for (const auto& n : f.notes) rec.add_notes(n);
  auto* rel = rec.mutable_release();
  rel->set_volume_on_mesh_m3(su.volume_on_mesh);
  auto* mb = rec.mutable_mass_balance();
  mb->set_volume_initial_m3(sum.volume_initial);
  mb->set_volume_final_m3(sum.volume_final);
  mb->set_volume_outflow_m3(sum.volume_outflow);
  mb->set_relative_error(sum.volume_error);
  f.fig.write(rec);  // solver: steps, alpha bounds, active cells; results: peak speed
  auto* so = rec.mutable_solver();
  so->set_simulated_s(sum.t);
  so->set_stop(sum.stop);
  if (!std::isnan(f.continued_from)) so->set_continued_from_t_s(f.continued_from);
  so->set_max_speed_m_s(sum.max_speed);
  auto* re = rec.mutable_results();
  record_hazard_results(r, sum, f.outputs, *re);
  for (const auto& line : f.outputs.parameters) rec.add_parameters(line);
  re->set_frames(f.frames);
  write_profiles(f, rec);
  record_structures(sum, rec);
  auto* ti = rec.mutable_timings_s();
  ti->set_prepare(sum.seconds_prepare);
  ti->set_run(sum.seconds_run);
  ti->set_write(sum.seconds_write);
  ti->set_microseconds_per_cell_step(f.fig.steps ? 1e6 * sum.seconds_run / double(f.fig.steps) / su.mesh.cells() : NAN);
  ti->set_microseconds_per_active_cell_step(f.fig.active_sum > 0 ? 1e6 * sum.seconds_run / f.fig.active_sum : NAN);
  for (const auto& file : sum.files) rec.add_outputs(file);
  rec.add_outputs("run.json");
  rec.mutable_execution()->set_petsc_options(petsc_options());
  if (f.backend) record_distribution(*f.backend, long(f.fig.steps), rec);
  write_run_record(path, rec);
}

}  // namespace runout::jobs::vof_terrain
