// Engine "vof": the laboratory block, completed and checked by its option table (lab_options.cpp),
// then the checks between its fields.
#include <algorithm>
#include <cmath>
#include <string>

#include "jobs/scenario/model_fields.hpp"
#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario.hpp"
#include "jobs/scenario/scenario_impl.hpp"

namespace runout::jobs {

namespace {

void check_obstacles(const v1::Lab& l, bool three_d) {
  for (int k = 0; k < l.obstacles_size(); ++k) {
    const auto& o = l.obstacles(k);
    const std::string f = "lab.obstacles[" + std::to_string(k) + "]";
    if (o.shape() == "polygon") {
      if (o.polygon_xy_size() < 6 || o.polygon_xy_size() % 2) bad(f + ".polygon_xy", "needs x, y pairs of at least 3 corners");
      continue;
    }
    if (!three_d) bad(f + ".shape", "'" + o.shape() + "' needs a 3D set-up (lab.nz > 0)");
    if (o.shape() == "cylinder" && !(o.radius() > 0 && o.height() > 0)) bad(f + ".radius", "a cylinder needs radius > 0 and height > 0");
    if (o.shape() != "cylinder" && !(o.edge() > 0)) bad(f + ".edge", "a tetrahedron needs edge > 0");
  }
}

void check_chute(const v1::Lab& l, bool three_d) {
  const auto& c = l.chute();
  if (!three_d) bad("lab.chute", "a curved chute needs a 3D set-up (lab.nz > 0)");
  if (l.y_min() != 0) bad("lab.y_min", "must be 0 with a chute (y is the height above its bed)");
  if (!(c.bend_deg() > 0)) bad("lab.chute.bend_deg", "must lie in (0, 90) deg");
  if (!(c.bend_end_m() > c.bend_start_m() && c.bend_start_m() > l.x_min())) bad("lab.chute.bend_end_m", "needs x_min < bend_start_m < bend_end_m");
  // The normals of the bend meet at its centre of curvature: the mesh must stay below it.
  const double radius = (c.bend_end_m() - c.bend_start_m()) / (c.bend_deg() * 3.14159265358979323846 / 180);
  const double zmax = std::max(std::abs(l.z_min()), std::abs(l.z_max()));
  const double bed_max = c.channel_radius_m() > 0 ? zmax * zmax / (2 * c.channel_radius_m()) : 0;
  if (!(l.y_max() + bed_max < 0.9 * radius))
    bad("lab.y_max", "the mesh (" + std::to_string(l.y_max() + bed_max) + " m above the reference surface) must stay well below the bend's radius of curvature (" +
                         std::to_string(radius) + " m)");
  if (!l.obstacles().empty()) bad("lab.obstacles", "obstacles are not supported on a curved chute");
  if (l.bed_normal_stress() == "column")
    bad("lab.bed_normal_stress", "\"column\" needs a plane bed: the curved chute's centripetal load is not in the laboratory's columns");
}

void check_fill(const v1::Lab& l, bool three_d) {
  for (int k = 0; k < l.fill_size(); ++k) {
    const auto& f = l.fill(k);
    const std::string fk = "lab.fill[" + std::to_string(k) + "]";
    if (f.cap_radius() != 0 || f.cap_height() != 0) {
      if (!three_d) bad(fk + ".cap_radius", "a spherical cap needs a 3D set-up (lab.nz > 0)");
      if (!(f.cap_radius() > 0 && f.cap_height() > 0 && f.cap_height() <= f.cap_radius()))
        bad(fk + ".cap_height", "a cap needs cap_radius > 0 and 0 < cap_height <= cap_radius");
    } else if (f.polygon_xy_size() > 0) {
      if (f.polygon_xy_size() < 6 || f.polygon_xy_size() % 2) bad(fk + ".polygon_xy", "needs x, y pairs of at least 3 corners");
    } else if (!(f.x_max() > f.x_min() && f.y_max() > f.y_min())) {
      bad(fk, "needs x_max > x_min and y_max > y_min (or polygon_xy)");
    }
  }
}

void check_boundaries(const v1::Lab& l, bool three_d) {
  for (int k = 0; k < l.boundaries_size(); ++k) {
    const auto& b = l.boundaries(k);
    const std::string f = "lab.boundaries[" + std::to_string(k) + "]";
    if (!three_d && (b.side() == "back" || b.side() == "front")) bad(f + ".side", "'" + b.side() + "' needs a 3D set-up (lab.nz > 0)");
    if (b.kind() == "inflow" && !(b.inflow_height() > 0)) bad(f + ".inflow_height", "an inflow needs a fill height > 0 m");
    if (b.kind() == "inflow" && b.side() != "left") bad(f + ".side", "inflow is supported on the left side only");
    if (b.has_from() && b.has_to() && !(b.to() > b.from())) bad(f + ".to", "must exceed from");
    if (l.has_chute() && (b.has_from() || b.has_to())) bad(f + ".from", "a curved chute takes whole sides only (no from/to)");
    if (l.has_chute() && b.kind() == "inflow") bad(f + ".kind", "inflow is not supported on a curved chute");
  }
}

// The upstream extent of an obstacle along x [m].
double obstacle_upstream_x(const v1::LabObstacle& o) {
  if (o.shape() == "cylinder") return o.x() - o.radius();
  if (o.shape() == "polygon") {
    double x = o.polygon_xy(0);
    for (int q = 0; q + 1 < o.polygon_xy_size(); q += 2) x = std::min(x, o.polygon_xy(q));
    return x;
  }
  // A tetrahedron's footprint: an equilateral triangle whose corners lie a / sqrt(3) from its centre,
  // a corner upstream (edge first) or a side a / (2 sqrt(3)) upstream (face first; geometry.cpp).
  const double r = o.edge() / std::sqrt(3.0);
  return o.x() - (o.shape() == "tetrahedron-edge" ? r : 0.5 * r);
}

// A nest (lab.nest): fed only by a whole left side's inflow on a fixed plane channel, its face inside
// the domain with at least 4 cells below it and upstream of every obstacle.
void check_nest(const v1::Lab& l) {
  if (!(l.nest().x_min() > l.x_min() && l.nest().x_min() < l.x_max())) bad("lab.nest.x_min", "must lie between lab.x_min and lab.x_max");
  const LabNestFace face = lab_nest_face(l);  // what the run takes: the checks below are on it
  const double x = face.x;
  if (face.cells < 4) bad("lab.nest.x_min", "leaves fewer than 4 cells to the 3D run");
  if (face.cells >= l.nx()) bad("lab.nest.x_min", "lies on the inflow (the nearest face of the cells is x_min): no chute above it");
  if (l.has_chute()) bad("lab.nest", "a nest needs a plane chute (not lab.chute)");
  if (l.rotation_period_s() > 0) bad("lab.nest", "a nest needs a fixed channel (not lab.rotation_period_s)");
  if (!l.fill().empty()) bad("lab.fill", "a nested laboratory run is fed only through its inflow (no fill regions)");
  int inflows = 0;
  for (const auto& b : l.boundaries())
    if (b.side() == "left") {
      if (b.kind() != "inflow" || b.has_from() || b.has_to()) bad("lab.boundaries", "a nest needs the whole left side an inflow (no from/to)");
      ++inflows;
    }
  if (inflows != 1) bad("lab.boundaries", "a nest needs the whole left side an inflow (the depth-averaged run's source)");
  for (int k = 0; k < l.obstacles_size(); ++k)
    if (obstacle_upstream_x(l.obstacles(k)) <= x)
      bad("lab.nest.x_min", "must lie upstream of lab.obstacles[" + std::to_string(k) + "] (the depth-averaged run does not see it; the face moves to " +
                                json_number(x) + " m, the nearest face of the cells)");
  for (int k = 0; k < l.stations_x_size(); ++k)
    if (l.stations_x(k) < x)
      bad("lab.stations_x[" + std::to_string(k) + "]", "lies above the nest's face (" + json_number(x) + " m): the 3D run does not cover it");
}

// The granular viscosity model with the lab block's parameters: each in its row's range and the
// model's own checks (engine/vof/models; for mu(I) the join of its branches).
void check_rheology(const v1::Lab& l) {
  engine::vof::VofConfig c;
  c.rho1 = lab_material(l.material()).rho;
  apply_lab_rheology(l, c);
  check_model(c, ModelBlock::lab);
}

}  // namespace

LabNestFace lab_nest_face(const v1::Lab& l) {
  const double dx = (l.x_max() - l.x_min()) / l.nx();
  LabNestFace f;
  f.cells = int(std::lround((l.x_max() - l.nest().x_min()) / dx));
  f.x = l.x_max() - f.cells * dx;
  return f;
}

void apply_lab_rheology(const v1::Lab& l, engine::vof::VofConfig& c) {
  if (l.has_side_wall_width_m()) {
    c.side_walls.width = l.side_wall_width_m();
    c.side_walls.tan_delta = std::tan(radians(l.side_wall_friction_deg()));
  }
  if (!l.rheology().empty()) c.rheology = l.rheology();
  // The models' parameters: the lab material's (options.hpp), then those the block gives.
  for (const auto& [field, value] : lab_model_defaults(lab_material(l.material()))) set_model_parameter(field, value, c);
  take_model_fields(l, ModelBlock::lab, c);
}

ResolvedScenario resolve_lab(v1::Scenario s) {
  if (!s.has_lab()) bad("lab", "engine \"vof\" needs the lab block (domain, cells, fill, boundaries)");
  if (s.has_mesh() || s.has_vof()) bad(s.has_mesh() ? "mesh" : "vof", "not used by a laboratory set-up (`lab`)");
  const double write_given = s.lab().write_interval_s();
  apply_option_rules(lab_options(), s);
  s.mutable_lab()->set_write_interval_s(default_frame_interval(write_given, s.lab().write_interval_s(), s.lab().end_time_s()));
  const auto& l = s.lab();
  if (!(l.x_max() > l.x_min())) bad("lab.x_max", "must exceed lab.x_min");
  if (!(l.y_max() > l.y_min())) bad("lab.y_max", "must exceed lab.y_min");
  if (l.nz() > 0 && !(l.z_max() > l.z_min())) bad("lab.z_max", "must exceed lab.z_min");
  if (double(l.nx()) * l.ny() * std::max(1, l.nz()) > 4e6) bad("lab.nx", "more than 4 million cells");
  const bool three_d = l.nz() > 0;
  check_obstacles(l, three_d);
  bool fed = false;
  for (const auto& b : l.boundaries()) fed |= b.kind() == "inflow";
  if (l.fill().empty() && !fed && !l.has_nest()) bad("lab.fill", "at least one region of granular material is needed (or an inflow)");
  if (l.has_chute()) check_chute(l, three_d);
  check_fill(l, three_d);
  check_boundaries(l, three_d);
  check_rheology(l);
  if (l.has_nest()) check_nest(l);
  if (l.has_side_wall_width_m() != l.has_side_wall_friction_deg())
    bad(l.has_side_wall_width_m() ? "lab.side_wall_friction_deg" : "lab.side_wall_width_m",
        "the side walls need both their width and their friction angle");
  if (l.has_side_wall_width_m() && three_d) bad("lab.side_wall_width_m", "only for plane set-ups (a 3D set-up has its own side walls)");
  const auto& ref = l.reference();
  if (ref.has_front_x_min() != ref.has_front_x_max() || (ref.has_front_x_min() && ref.front_x_max() < ref.front_x_min()))
    bad("lab.reference.front_x_max", "the front is a range: give front_x_min and front_x_max >= front_x_min");
  check_output_interval("lab.write_interval_s", l.write_interval_s(), "lab.end_time_s", l.end_time_s(), false);
  check_output_interval("lab.checkpoint_interval_s", l.checkpoint_interval_s(), "lab.end_time_s", l.end_time_s(), true);
  require_finite(s, "");
  ResolvedScenario r;
  r.engine = kVofLabEngine;
  r.scenario = std::move(s);
  return r;
}

}  // namespace runout::jobs
