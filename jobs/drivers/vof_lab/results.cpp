#include "jobs/drivers/vof_lab/results.hpp"

#include <algorithm>
#include <cmath>

#include "jobs/formats/run_record.hpp"

namespace runout::jobs::vof_lab {

namespace vof = engine::vof;
constexpr double kPi = 3.14159265358979323846;

void write_mesh(const LabSetup& su, v1::RunRecord& rec) {
  const auto& g = su.g;
  auto* me = rec.mutable_mesh();
  me->set_cells(su.m.cells());
  me->set_nx(g.nx);
  me->set_ny(g.ny);
  me->set_nz(g.three_d ? g.nz : 0);
  me->set_dx_m(g.dx);
  me->set_dy_m(g.dy);
  if (g.three_d) me->set_dz_m(g.dz);
}

Deposit deposit(const LabSetup& su, const vof::VofBackend& s) {
  const auto& g = su.g;
  const double dx = g.dx, dy = g.dy;
  Deposit d;
  d.h.assign(std::size_t(g.nx), 0.0);
  auto& h = d.h;
  for (int k = 0; k < su.m.cells(); ++k) {
    const auto& p = su.local[std::size_t(k)];  // bed coordinates (on a curved chute: arc length)
    h[std::size_t(std::clamp(int((p.x - g.x0) / dx), 0, g.nx - 1))] += s.alpha()[std::size_t(k)] * dy * g.dz / g.width;
    d.volume += s.alpha()[std::size_t(k)] * su.m.volume[std::size_t(k)];
  }
  double front = g.x0, hmax = 0;
  for (int i = 0; i < g.nx; ++i) {
    if (h[std::size_t(i)] >= 0.5 * dy) front = g.x0 + (i + 1) * dx;  // at least half a cell of material
    hmax = std::max(hmax, h[std::size_t(i)]);
  }
  // Surface angles right of the highest column: the upper surface (least-squares slope of the
  // column heights between 90 % and 50 % of the highest) and the mean slope from 80 % to 20 %.
  int imax = int(std::max_element(h.begin(), h.end()) - h.begin());
  while (imax + 1 < g.nx && h[std::size_t(imax) + 1] >= 0.999 * hmax) ++imax;  // the plateau's right end
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (int i = imax; i < g.nx; ++i)
    if (h[std::size_t(i)] < 0.9 * hmax && h[std::size_t(i)] > 0.5 * hmax) {
      const double xx = g.x0 + (i + 0.5) * dx;
      sx += xx, sy += h[std::size_t(i)], sxx += xx * xx, sxy += xx * h[std::size_t(i)], n += 1;
    }
  d.upper_angle = n >= 2 ? std::atan(-(n * sxy - sx * sy) / (n * sxx - sx * sx)) * 180 / kPi : NAN;
  double xh = NAN, xl = NAN;
  for (int i = imax; i < g.nx; ++i) {
    if (std::isnan(xh) && h[std::size_t(i)] < 0.8 * hmax) xh = g.x0 + (i + 0.5) * dx;
    if (std::isnan(xl) && h[std::size_t(i)] < 0.2 * hmax) xl = g.x0 + (i + 0.5) * dx;
  }
  d.mean_angle = (std::isnan(xh) || std::isnan(xl) || xl <= xh) ? NAN : std::atan(0.6 * hmax / (xl - xh)) * 180 / kPi;
  d.front = front;
  d.height = hmax;
  d.imax = imax;
  return d;
}

void write_deposit(const Deposit& d, const LabSetup& su, int frames, v1::RunRecord& rec) {
  auto* re = rec.mutable_results();
  re->set_front_x_m(d.front);
  re->set_deposit_height_m(d.height);
  re->set_upper_surface_angle_deg(d.upper_angle);
  re->set_mean_surface_angle_deg(d.mean_angle);
  re->set_volume_initial_m3(su.v0);
  re->set_volume_final_m3(d.volume);
  re->set_volume_relative_error(su.has_inflow ? NAN : std::abs(d.volume - su.v0) / su.v0);  // material comes in: no conservation figure
  re->set_frames(frames);
}

// Cells blocked by an obstacle are skipped: on a ramp the column starts at the ramp's surface.
void write_stations(const v1::Lab& L, const LabSetup& su, const vof::VofBackend& s, v1::RunRecord& rec) {
  const auto& g = su.g;
  const double dy = g.dy;
  for (int q = 0; q < L.stations_x_size(); ++q) {
    const double xs = L.stations_x(q);
    const int i = std::clamp(int((xs - g.x0) / g.dx), 0, g.nx - 1);
    double depth = 0, flux = 0, surface = NAN, basal = NAN, basal_speed = NAN, bed = NAN;
    double sy = 0, su_ = 0, syy = 0, syu = 0, nn = 0;
    auto* st = rec.add_stations();
    for (int jj = 0; jj < g.ny; ++jj) {
      const int c = g.id(i, jj, g.kc);
      if (c < 0) continue;
      const auto k = std::size_t(c);
      const double y = g.y0 + (jj + 0.5) * dy;
      if (std::isnan(bed)) bed = y - 0.5 * dy;
      const double a = std::clamp(s.alpha()[k], 0.0, 1.0), u = s.velocity()[k].x;
      depth += a * dy;
      flux += a * u * dy;
      if (a > 0.5) {
        if (std::isnan(basal)) basal = u, basal_speed = vof::norm(s.velocity()[k]);
        surface = u;
        sy += y, su_ += u, syy += y * y, syu += y * u, nn += 1;
      }
      *st->add_profile_y_alpha_u() = profile_point(y, a, u);
    }
    st->set_x_m(xs);
    st->set_bed_y_m(bed);
    st->set_depth_m(depth);
    st->set_depth_averaged_u_m_s(depth > 0 ? flux / depth : NAN);
    st->set_surface_u_m_s(surface);
    st->set_basal_u_m_s(basal);
    st->set_basal_speed_m_s(basal_speed);
    st->set_strain_rate_1_s(nn >= 3 ? (nn * syu - sy * su_) / (nn * syy - sy * sy) : NAN);
  }
}

namespace {

// The flow depth per column (x, z) and the depth-averaged velocity along the bed and across it.
void depth_map(const v1::Lab& L, const LabSetup& su, const vof::VofBackend& s, std::vector<double>& d, std::vector<char>& blocked_col,
               figures::PlanFigure& plan) {
  const auto& g = su.g;
  const ChuteBed chute_bed(L);  // used on a curved chute only
  d.assign(std::size_t(g.nx) * g.nz, 0.0);
  blocked_col.assign(d.size(), 0);
  plan.ux.assign(d.size(), 0.0);
  plan.uz.assign(d.size(), 0.0);
  for (int k = 0; k < g.nz; ++k)
    for (int i = 0; i < g.nx; ++i)
      for (int j = 0; j < g.ny; ++j) {
        const int c = g.id(i, j, k);
        const std::size_t col = std::size_t(k) * g.nx + i;
        if (c < 0) {
          blocked_col[col] = 1;
          continue;
        }
        const double a = std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0) * g.dy;
        const auto& u = s.velocity()[std::size_t(c)];
        d[col] += a;
        // Along the bed: on a curved chute along the reference curve's tangent at the cell.
        const double ta = L.has_chute() ? chute_bed.angle(su.local[std::size_t(c)].x) : 0.0;
        plan.ux[col] += a * (u.x * std::cos(ta) + u.y * std::sin(ta));
        plan.uz[col] += a * u.z;
      }
  plan.depth.resize(d.size());
  for (std::size_t col = 0; col < d.size(); ++col) {
    if (d[col] > 0) plan.ux[col] /= d[col], plan.uz[col] /= d[col];
    plan.depth[col] = blocked_col[col] && d[col] < 1e-3 ? NAN : d[col];  // grey: an obstacle not covered by flow
  }
}

// Per obstacle the dry area (depth below 1 mm) in its shadow: from the centre (a polygon across the
// width: from its downstream end) 15 cm downstream, as wide as the obstacle (a polygon: the whole
// width).
void shadows(const v1::Lab& L, const LabGrid& g, const std::vector<double>& d, const std::vector<char>& blocked_col, figures::PlanFigure& plan,
             v1::Chute& rec) {
  for (int q = 0; q < L.obstacles_size(); ++q) {
    const auto& o = L.obstacles(q);
    const bool poly = o.shape() == "polygon";
    double wx0 = o.x(), wz0 = o.z() - 0.5 * o.edge(), wz1 = o.z() + 0.5 * o.edge();
    if (o.shape() == "cylinder") wz0 = o.z() - o.radius(), wz1 = o.z() + o.radius();
    if (poly) {
      wx0 = -1e300, wz0 = g.z0, wz1 = g.z0 + g.width;
      for (int q2 = 0; q2 + 1 < o.polygon_xy_size(); q2 += 2) wx0 = std::max(wx0, o.polygon_xy(q2));
    }
    const double wx1 = wx0 + 0.15;
    double dry = 0;
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        const double x = g.x0 + (i + 0.5) * g.dx, z = g.z0 + (k + 0.5) * g.dz;
        if (x > wx0 && x < wx1 && z > wz0 && z < wz1 && !blocked_col[std::size_t(k) * g.nx + i] && d[std::size_t(k) * g.nx + i] < 1e-3)
          dry += g.dx * g.dz;
      }
    auto* sh = rec.add_obstacles();
    sh->set_shape(o.shape());
    sh->set_sheltered_dry_area_m2(dry);
    plan.shadows.push_back({o.shape() == "cylinder"           ? "cylinder"
                            : o.shape() == "tetrahedron-edge" ? "tetrahedron (edge upstream)"
                            : o.shape() == "tetrahedron-face" ? "tetrahedron (face upstream)"
                                                              : o.shape(),
                            wx0, wx1, wz0, wz1, dry});
  }
}

// The curved chute (validation.md B8): where the deposit lies along the arc length (on the chute,
// in the bend, on the run-out), its extent, its half-width on the chute and on the run-out (z from
// lab.z_min, the symmetry plane of a half chute), its highest point and centroid.
void curved_chute(const v1::Lab& L, const LabSetup& su, const vof::VofBackend& s, const std::vector<double>& d, const figures::PlanFigure& plan,
                  v1::CurvedChute& rec) {
  const auto& g = su.g;
  const double s1 = L.chute().bend_start_m(), s2 = L.chute().bend_end_m();
  double vol[3] = {0, 0, 0}, sm = 0, mv = 0, smin = NAN, smax = NAN, w_chute = 0, w_run = 0;
  for (int c = 0; c < su.m.cells(); ++c) {
    const double v = std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0) * su.m.volume[std::size_t(c)], x = su.local[std::size_t(c)].x;
    vol[x < s1 ? 0 : x <= s2 ? 1 : 2] += v;
    sm += v * x, mv += v;
  }
  for (int k = 0; k < g.nz; ++k)
    for (int i = 0; i < g.nx; ++i) {
      if (d[std::size_t(k) * g.nx + i] < 1e-3) continue;
      const double x = g.x0 + (i + 0.5) * g.dx, z = std::abs(g.z0 + (k + 1) * g.dz - L.z_min());
      smin = std::isnan(smin) ? x : std::min(smin, x), smax = std::isnan(smax) ? x : std::max(smax, x);
      if (x < s1) w_chute = std::max(w_chute, z);
      if (x > s2) w_run = std::max(w_run, z);
    }
  const double tot = std::max(mv, 1e-300);
  rec.set_share_on_chute(vol[0] / tot);
  rec.set_share_in_bend(vol[1] / tot);
  rec.set_share_on_runout(vol[2] / tot);
  rec.set_deposit_from_m(smin);
  rec.set_deposit_to_m(smax);
  rec.set_half_width_on_chute_m(w_chute);
  rec.set_half_width_on_runout_m(w_run);
  rec.set_highest_x_m(plan.deepest_x);
  rec.set_highest_z_m(plan.deepest_z);
  rec.set_highest_depth_m(plan.deepest);
  rec.set_centroid_x_m(sm / tot);
}

}  // namespace

// The undisturbed depth (median over the wetted columns of the first quarter of the chute), the
// deepest column and its ratio to it, and the obstacles' shadows.
void write_chute(const v1::Lab& L, const LabSetup& su, const vof::VofBackend& s, figures::PlanFigure& plan, v1::RunRecord& rec) {
  const auto& g = su.g;
  std::vector<double> d, upstream;
  std::vector<char> blocked_col;
  depth_map(L, su, s, d, blocked_col, plan);
  double dmax = 0, xm = NAN, zm = NAN;
  for (int k = 0; k < g.nz; ++k)
    for (int i = 0; i < g.nx; ++i) {
      const double v = d[std::size_t(k) * g.nx + i];
      if (i < g.nx / 4 && v > 0.5 * g.dy && !blocked_col[std::size_t(k) * g.nx + i]) upstream.push_back(v);
      if (v > dmax) dmax = v, xm = g.x0 + (i + 0.5) * g.dx, zm = g.z0 + (k + 0.5) * g.dz;
    }
  std::sort(upstream.begin(), upstream.end());
  const double und = upstream.empty() ? NAN : upstream[upstream.size() / 2];
  plan.nx = g.nx, plan.nz = g.nz, plan.x0 = g.x0, plan.z0 = g.z0, plan.dx = g.dx, plan.dz = g.dz;
  if (L.has_chute()) plan.xlabel = "arc length [m]";
  plan.undisturbed = und, plan.deepest = dmax, plan.deepest_x = xm, plan.deepest_z = zm;
  if (L.has_reference()) {
    plan.ref_source = L.reference().source();
    if (L.reference().has_depth_ratio_max()) plan.ref_depth_ratio = L.reference().depth_ratio_max();
  }
  auto* ch = rec.mutable_chute();
  ch->set_undisturbed_depth_m(und);
  ch->set_max_depth_m(dmax);
  ch->set_max_depth_x_m(xm);
  ch->set_max_depth_z_m(zm);
  ch->set_max_depth_ratio(und > 0 ? dmax / und : NAN);
  shadows(L, g, d, blocked_col, plan, *ch);
  if (L.has_chute()) curved_chute(L, su, s, d, plan, *rec.mutable_curved_chute());
}

}  // namespace runout::jobs::vof_lab
