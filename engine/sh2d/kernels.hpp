#pragma once
// The depth-averaged 2D scheme's equations as point kernels: inline functions of one cell or one face
// that take plain values (or arrays and an index) and return the result. The general cell loops
// (domain edges, cells next to the outside) and the branch-free row kernels (the interior, compiled
// for vectorisation) call the same kernels, so every cell gets the same bits whichever loop computes
// it. The kernels are written branch-free: every value is computed and selects pick the result
// (exact), so that they vectorise inside the row loops; no select loads on one side only.
#include <cmath>
#include <cstddef>

#include "engine/friction/law.hpp"
#include "engine/limiters.hpp"
#include "engine/rheology.hpp"

// The kernels are always inlined: a call in a row kernel's loop would keep it from vectorising.
#if defined(__GNUC__)
#define RUNOUT_KERNEL [[gnu::always_inline]] inline
#else
#define RUNOUT_KERNEL inline
#endif

namespace runout::engine::sh2d_detail {

// std::max and std::min by value (the same selects): the kernels take them of locals, and a
// reference to a local in an OpenMP simd loop keeps the compiler from vectorising it.
RUNOUT_KERNEL double vmax(double a, double b) { return a < b ? b : a; }
RUNOUT_KERNEL double vmin(double a, double b) { return b < a ? b : a; }

struct Face {
  double f0, f1, f2;
};

// A reconstructed state on one side of a face, in face coordinates: depth, normal and tangential
// velocity, and the pressure coefficients Pi_nn, Pi_nt of that side's cell.
struct FaceState {
  double H, un, ut, Pnn, Pnt;
};

// The basal friction a kernel computes, a template parameter (no branch in the loops): a constant mu
// with or without Voellmy's drag, or mu(h, Fr) with or without the start/stop term
// (engine/friction/law.hpp); `ground`: a constant mu with Voellmy's drag (1/xi may be 0) and, per
// cell, what lies on the ground: the drag and the detrainment of resistance areas
// (Sh2dConfig::resistance) and the erodible cover (Sh2dConfig::cover).
enum class Basal { coulomb, voellmy, flow, hysteresis, ground };
constexpr bool is_flow(Basal b) { return b == Basal::flow || b == Basal::hysteresis; }

// What the ground's terms read (engine/sh2d.hpp ResistanceAreas, ErodibleCover): where a resistance
// area's drag and detrainment act (the band of normal depth and speed of the drag, detrain = 1 where
// detrainment is on (below either minimum), else 0 (the drag everywhere)), 1 / the flow's density;
// the cover's erosion: 1 / e_b (0 while ploughing), plough = 1 for front entrainment, else 0, and the
// flowing depth at which a cell ploughs its cover.
struct GroundRule {
  double speed_min, speed_max, depth_min, depth_max, detrain, inv_density;
  double inv_eb, plough, flowing;
};

// The constants of one step the kernels read: gravity g, the cap of the centrifugal term qcap, the
// dry depth, curv = 1 where the centrifugal part raises the friction's load (option `curvature`),
// else 0, and the friction law.
struct StepConstants {
  double g, qcap, dry, curv;
  BasalFriction fr;
  GroundRule ground{};  // Basal::ground only
};

// ---- Surface and load ------------------------------------------------------------------------

// The 3D magnitude of a horizontal vector (x, y) on a surface of gradient (bx, by): its vertical
// component is bx x + by y.
RUNOUT_KERNEL double speed3(double bx, double by, double x, double y) {
  const double w = bx * x + by * y;
  return std::sqrt(x * x + y * y + w * w);
}

// The normal reaction per unit mass, (g + Q)_+, with the centrifugal term Q = u^T Hess(z) u capped
// at qcap. It keeps the flow on the surface and always includes Q: it turns the velocity in curved
// terrain without loss of energy.
RUNOUT_KERNEL double normal_load(double U, double V, double hxx, double hxy, double hyy, double g, double qcap) {
  return vmax(0.0, g + vmin(qcap, U * U * hxx + 2 * U * V * hxy + V * V * hyy));
}

// The load of the basal friction: (g + Q)_+ with the option `curvature` (as in eq. 3.48 and in the
// 1D solver), else g. As 0/1 weights, exact because gn and g are finite (a select on the option
// would keep the compiler from vectorising).
RUNOUT_KERNEL double friction_load(const StepConstants& k, double gn) { return k.curv * gn + (1.0 - k.curv) * k.g; }

// ---- Basal friction --------------------------------------------------------------------------

// The friction coefficient at normal depth h, 3D speed `speed` and normal stress gc (c times the
// friction's load, so that Fr = speed / sqrt(gc h)). The start/stop law's takes its parts (mu
// without the term and the term's weight q^kappa) from the caller, who computes the power outside
// the vectorised loops (start_parts, start_weight).
template <Basal B>
RUNOUT_KERNEL double basal_mu(const BasalFriction& fr, double h, double speed, double gc, double smu, double sw) {
  if constexpr (B == Basal::flow) return flow_mu<false>(fr, h, speed, gc);
  else if constexpr (B == Basal::hysteresis) return with_start(fr, smu, sw);
  else return fr.mu;
}

// The start/stop law's parts of a cell at depth H and velocity (U, V): mu without the start/stop
// term and q (engine/friction/law.hpp flow_mu_parts), with the load of basal_mu.
RUNOUT_KERNEL MuParts start_parts(const StepConstants& k, double H, double U, double V, double c, double bx, double by,
                                  double hxx, double hxy, double hyy) {
  const double gn = normal_load(U, V, hxx, hxy, hyy, k.g, k.qcap);
  return flow_mu_parts(k.fr, H * c, speed3(bx, by, U, V), c * friction_load(k, gn));
}

// Coulomb resistance per horizontal area (magnitude of the basal friction force, 3D):
// mu N / cos(theta) with N / rho = h c load = H c^2 load.
RUNOUT_KERNEL double resistance(double H, double mu, double c, double load) { return H * mu * c * load; }

// Coulomb friction as a bounded impulse against momentum of 3D magnitude m3 (engine/rheology.hpp
// apply_friction, as selects): the factor that shrinks it, never reversing it; `stopped` where the
// impulse brings it to rest (the momentum is then 0 and the factor not used).
RUNOUT_KERNEL double friction_factor(double m3, double impulse) { return 1.0 - impulse / m3; }
RUNOUT_KERNEL bool stopped(double m3, double impulse) { return m3 <= impulse; }

// Voellmy's drag, implicit (engine/rheology.hpp turbulent_factor) for normal depth h > 0; 1 where the
// speed is 0. The depth is bounded away from 0 so that a dry cell's factor stays finite.
RUNOUT_KERNEL double drag_factor(double speed, double h, double gxd) { return turbulent_factor(speed, vmax(h, 1e-300), gxd); }

// The weight of a resistance area's drag at normal depth h and speed: 1 inside the band of both (or
// everywhere without detrainment), else 0. As 0/1 weights: the selects stay branch-free.
RUNOUT_KERNEL double drag_weight(const GroundRule& r, double h, double speed) {
  const bool band = h >= r.depth_min && h <= r.depth_max && speed >= r.speed_min && speed <= r.speed_max;
  return r.detrain == 0.0 || band ? 1.0 : 0.0;
}
// Whether a resistance area detrains at normal depth h and speed: detrainment on and slower than
// the band or thinner than it.
RUNOUT_KERNEL bool detrains(const GroundRule& r, double h, double speed) {
  return r.detrain != 0.0 && (h < r.depth_min || speed < r.speed_min);
}

// The depth (as H of flow) a cell takes up from its erodible cover cov (as H) in one step: basal
// erosion tau_b |u| dt / (rho e_b) per horizontal area (tau_dt = tau_b dt / rho per horizontal area,
// speed the 3D speed), at most the cover; or, ploughing, the whole cover where the normal depth h
// flows.
RUNOUT_KERNEL double ground_entrainment(const GroundRule& r, double tau_dt, double speed, double h, double cov) {
  const double eroded = vmin(tau_dt * speed * r.inv_eb, cov);
  const double ploughed = h > r.flowing ? cov : 0.0;
  return r.plough != 0.0 ? ploughed : eroded;
}

// ---- Reconstruction and predictor --------------------------------------------------------------

struct Slopes {
  double Hx, ux, vx, Hy, uy, vy;
};

// Limited slopes of the depth and of the velocity of cell k (primitive variables: reconstructing the
// velocity rather than the momentum keeps thin layers from producing spurious speeds). l, r, b, a:
// the offsets of the neighbours left, right, below, above; tx, ty: the x, y slopes are taken (the
// cell and both neighbours in the domain; the offsets may be 0 where not). The velocity's slopes
// only between wet neighbours.
template <Limiter L>
RUNOUT_KERNEL Slopes limited_slopes(const double* H, const double* U, const double* V, std::ptrdiff_t k, std::ptrdiff_t l,
                                    std::ptrdiff_t r, std::ptrdiff_t b, std::ptrdiff_t a, bool tx, bool ty, double dry) {
  const double h = H[k], u = U[k], v = V[k];
  const bool wx = tx && vmin(H[k + l], H[k + r]) > dry, wy = ty && vmin(H[k + b], H[k + a]) > dry;
  const double sHx = limited_slope(L, h - H[k + l], H[k + r] - h), sHy = limited_slope(L, h - H[k + b], H[k + a] - h);
  const double sux = limited_slope(L, u - U[k + l], U[k + r] - u), svx = limited_slope(L, v - V[k + l], V[k + r] - v);
  const double suy = limited_slope(L, u - U[k + b], U[k + a] - u), svy = limited_slope(L, v - V[k + b], V[k + a] - v);
  return Slopes{tx ? sHx : 0.0, wx ? sux : 0.0, wx ? svx : 0.0, ty ? sHy : 0.0, wy ? suy : 0.0, wy ? svy : 0.0};
}

// The cell's values at the half step.
struct Predicted {
  double Hp, Up, Vp;
  double held;  // 1 where friction holds the cell at rest (it was at rest and stays), else 0
};

// The predictor to t + dt/2 of a cell at (H, U, V) with momentum (HU, HV) and slopes s (eq. 4.78 in
// primitive form, pressure coefficients Pxx, Pxy, Pyy frozen in the cell; hx = dt / (2 dx),
// hy = dt / (2 dy)); where a predicted face depth would be negative it falls back to first order and
// zeroes s. Then friction over the half step with the load and mu of the state at t (mu from
// basal_mu, the start/stop law's parts smu, sw), and Voellmy's drag implicitly (B), with a resistance
// area's drag coefficient cres (Basal::ground) in its band at the state at t.
template <Basal B>
RUNOUT_KERNEL Predicted predict(const StepConstants& k, double H, double U, double V, double HU, double HV, Slopes& s,
                                double Pxx, double Pxy, double Pyy, double c, double bx, double by, double hxx, double hxy,
                                double hyy, double hx, double hy, double dt, double gxd, double smu, double sw,
                                double cres = 0) {
  const double gn = normal_load(U, V, hxx, hxy, hyy, k.g, k.qcap);
  const double acc = -c * c * gn;  // gravity + normal reaction per unit volume
  const bool wet = H > k.dry;
  const double Hp1 = H - hx * (U * s.Hx + H * s.ux) - hy * (V * s.Hy + H * s.vy);
  const double Up1 = U - hx * (U * s.ux + Pxx * s.Hx) - hy * (V * s.uy + Pxy * s.Hy) + 0.5 * dt * acc * bx;
  const double Vp1 = V - hx * (U * s.vx + Pxy * s.Hx) - hy * (V * s.vy + Pyy * s.Hy) + 0.5 * dt * acc * by;
  // First order where a predicted face depth would be negative.
  const bool bad = Hp1 - 0.5 * std::abs(s.Hx) - 0.5 * std::abs(s.Hy) < 0;
  s.Hx = bad ? 0.0 : s.Hx;
  s.ux = bad ? 0.0 : s.ux;
  s.vx = bad ? 0.0 : s.vx;
  s.Hy = bad ? 0.0 : s.Hy;
  s.uy = bad ? 0.0 : s.uy;
  s.vy = bad ? 0.0 : s.vy;
  const double Hp = bad ? H : Hp1;
  const double Up0 = bad ? U + 0.5 * dt * acc * bx : Up1, Vp0 = bad ? V + 0.5 * dt * acc * by : Vp1;
  const double Up = wet ? Up0 : 0.0, Vp = wet ? Vp0 : 0.0;
  const double load = friction_load(k, gn);
  const double mu = basal_mu<B>(k.fr, H * c, speed3(bx, by, U, V), c * load, smu, sw);
  const double imp = 0.5 * dt * resistance(1.0, mu, c, load), M3 = speed3(bx, by, Up, Vp);
  const bool rest = stopped(M3, imp);
  double f = friction_factor(M3, imp);
  if constexpr (B == Basal::voellmy) f *= drag_factor(vmax(M3 - imp, 0.0), H * c, gxd);
  if constexpr (B == Basal::ground) {
    const double gr = gxd + 0.5 * dt * cres * drag_weight(k.ground, H * c, speed3(bx, by, U, V));
    f *= drag_factor(vmax(M3 - imp, 0.0), H * c, gr);
  }
  const double held = std::abs(HU) + std::abs(HV) == 0.0 ? (rest ? 1.0 : 0.0) : 0.0;
  return Predicted{Hp, rest ? 0.0 : Up * f, rest ? 0.0 : Vp * f, held};
}

// ---- Face fluxes -----------------------------------------------------------------------------

// The state on one side of a face from its cell's predicted values and slopes in face coordinates:
// half = +0.5 on the cell's upper face, -0.5 on its lower face.
RUNOUT_KERNEL FaceState face_side(double Hp, double sH, double un, double sun, double ut, double sut, double Pnn,
                                  double Pnt, double half) {
  return FaceState{Hp + half * sH, un + half * sun, ut + half * sut, Pnn, Pnt};
}

// Ghost state beyond a domain edge: a wall mirrors the inside (normal velocity and the off-diagonal
// pressure coefficient change sign, so no mass crosses and the wall pushes only normally); an
// outflow boundary copies it.
RUNOUT_KERNEL FaceState boundary_ghost(const FaceState& in, bool wall) {
  return wall ? FaceState{in.H, -in.un, in.ut, in.Pnn, -in.Pnt} : in;
}

// Ghost state in a cell outside the domain: free outflow. The inside state is copied while it flows
// out; a flow towards the inside meets a mirror instead, so nothing comes in from where there is no
// terrain. `ghost_right`: the ghost lies on the face's right (upper) side.
RUNOUT_KERNEL FaceState outflow_ghost(const FaceState& in, bool ghost_right) {
  return boundary_ghost(in, ghost_right ? in.un < 0 : in.un > 0);
}

// The flux through a face (mass, normal momentum, tangential momentum): the central local-speed flux
// (Kurganov & Tadmor 2000) between the predicted face values; between two cells that friction holds
// at rest (held) the pressure only, no numerical diffusion, so that material at rest stays exactly
// at rest. The local speed bounds the characteristic speeds |u| + c on both sides with
// max|u| + sqrt(max c^2) (one square root instead of two). Raising it to the dry-bed front speed
// u + 2c at wet/dry faces was tried: it adds diffusion and makes thin fronts lag more
// (docs/design/depth-averaged.md).
RUNOUT_KERNEL Face face_flux(const FaceState& L, const FaceState& R, bool held) {
  const double a = vmax(std::abs(L.un), std::abs(R.un)) + std::sqrt(vmax(L.Pnn * vmax(L.H, 0.0), R.Pnn * vmax(R.H, 0.0)));
  const double mL = L.H * L.un, mR = R.H * R.un;
  const double pL = 0.5 * L.Pnn * L.H * L.H, pR = 0.5 * R.Pnn * R.H * R.H;
  const double qL = 0.5 * L.Pnt * L.H * L.H, qR = 0.5 * R.Pnt * R.H * R.H;
  const double f0 = 0.5 * (mL + mR) - 0.5 * a * (R.H - L.H);
  const double f1 = 0.5 * (mL * L.un + pL + mR * R.un + pR) - 0.5 * a * (mR - mL);
  const double f2 = 0.5 * (mL * L.ut + qL + mR * R.ut + qR) - 0.5 * a * (R.H * R.ut - L.H * L.ut);
  return Face{held ? 0.0 : f0, held ? 0.5 * (pL + pR) : f1, held ? 0.5 * (qL + qR) : f2};
}

// ---- Dams: step faces ------------------------------------------------------------------------

// The depth of a face side that reaches over a dam's step `rise` [m] above its own bed (<= 0: no step
// on this side): hydrostatic reconstruction (Audusse et al. 2004) with the side's run-up, the part of
// H + head above the step, at most H. The head is the velocity head towards the step (un_to >= 0,
// horizontal, on ground of slope s_n along the face normal, so the 3D speed's square is
// un_to^2 (1 + s_n^2)): a flow that could climb the dam's face without losses passes it.
RUNOUT_KERNEL double over_step(double H, double un_to, double s_n, double g, double rise) {
  const double head = un_to * un_to * (1 + s_n * s_n) / (2 * g);
  return rise > 0 ? vmin(H, vmax(0.0, H + head - rise)) : H;
}

// The flux a wall puts on a face side (`left`: the side left of the face, the wall right of it): the
// flux against its mirror (boundary_ghost): no mass, the pressure, the normal momentum turned back;
// between cells friction holds at rest (held) the pressure only, as face_flux.
RUNOUT_KERNEL Face wall_flux(const FaceState& in, bool left, bool held) {
  const FaceState m = boundary_ghost(in, true);
  return left ? face_flux(in, m, held) : face_flux(m, in, held);
}

// ---- Positivity limiter and update ---------------------------------------------------------------

// The draining-time factor of a cell holding H that would send out `out` in one step: the share it
// may send (1 when it holds enough).
RUNOUT_KERNEL double drain_factor(double out, double H) { return out > H ? H / out : 1.0; }

// The factor of a face's flux f0 > 0 / < 0: the sending cell's draining factor, rl on the left, rr on
// the right; as a sum of 0/1-weighted terms, exact because the factors lie in [0, 1] (as selects, the
// compiler would load rl and rr only in their branch and could not vectorise the loop).
RUNOUT_KERNEL double upwind_blend(double f0, double rl, double rr) {
  const double pos = f0 > 0 ? 1.0 : 0.0, neg = f0 < 0 ? 1.0 : 0.0;
  return pos * rl + neg * rr + (1.0 - pos - neg);
}

// A conserved quantity after one step from its fluxes through the faces west, east, south, north,
// scaled by the factors sw, se, ss, sn (lx = dt / dx, ly = dt / dy).
RUNOUT_KERNEL double flux_update(double Q0, double lx, double ly, double fw, double fe, double fs, double fn, double sw,
                                 double se, double ss, double sn) {
  return Q0 - lx * (fe * se - fw * sw) - ly * (fn * sn - fs * ss);
}

// A cell's new state: depth, momentum, velocity (zero where dry) and surface speed after friction.
struct NewState {
  double H, MU, MV, U, V, sp;
  double det, ent;  // depth detrained and entrained in the step (Basal::ground), as H
};

// The sources and friction of a cell whose depth H and momentum (MU, MV) are the flux update's:
// gravity and the normal reaction at the half step (Hp, Up, Vp; midpoint rule), then the friction
// at the half step as a bounded impulse that never reverses u, its load and mu from the half-step
// state, then Voellmy's drag implicitly in the speed (gxd = dt g / xi). Basal::ground: a resistance
// area's drag (coefficient cres, in its band at the half step) joins Voellmy's, and where the area
// detrains (kdet, Pa) the flow leaves dh = dt K / (rho |u|) of normal thickness per step behind
// (Feistl et al. 2014, as AvaFrame's com1DFA), dt K / (rho |u| c) of H, at most all of it, with its
// momentum. Then the erodible cover (cov, as H of flow) is eroded (ground_entrainment). Dry cells keep
// no momentum.
template <Basal B>
RUNOUT_KERNEL NewState update_sources(const StepConstants& k, double H, double MU, double MV, double Hp, double Up,
                                      double Vp, double c, double bx, double by, double hxx, double hxy, double hyy,
                                      double dt, double gxd, double smu, double sw, double cres = 0, double kdet = 0,
                                      double cov = 0) {
  H = H < 0 ? 0.0 : H;  // round-off only: the limiter bounds the outflow by the content
  const double gn = normal_load(Up, Vp, hxx, hxy, hyy, k.g, k.qcap);
  const double drive = -Hp * c * c * gn;
  MU = MU + dt * drive * bx;
  MV = MV + dt * drive * by;
  const double M3 = speed3(bx, by, MU, MV), load = friction_load(k, gn);
  const double mu = basal_mu<B>(k.fr, Hp * c, speed3(bx, by, Up, Vp), c * load, smu, sw);
  const double imp = dt * resistance(Hp, mu, c, load);
  const bool rest = stopped(M3, imp);
  const double f = friction_factor(M3, imp);
  MU = rest ? 0.0 : MU * f;
  MV = rest ? 0.0 : MV * f;
  double inv = 1.0 / H;
  double sp = vmax(M3 - imp, 0.0) * inv;  // surface speed after Coulomb friction
  const double up = B == Basal::ground ? speed3(bx, by, Up, Vp) : 0.0;  // the ground's terms read it
  if constexpr (B == Basal::voellmy || B == Basal::ground) {
    double g = gxd;
    if constexpr (B == Basal::ground) g += dt * cres * drag_weight(k.ground, Hp * c, up);
    const double ft = turbulent_factor(sp, H * c, g);
    MU *= ft;
    MV *= ft;
    sp *= ft;
  }
  double det = 0, ent = 0;
  if constexpr (B == Basal::ground) {
    const double dH = dt * kdet * k.ground.inv_density / (vmax(up, 1e-6) * c);
    det = kdet > 0 && detrains(k.ground, Hp * c, up) ? vmin(dH, H) : 0.0;
    const double keep = det > 0 ? (H - det) * inv : 1.0;  // exactly 1 where nothing detrains
    H = H - det;
    MU *= keep;
    MV *= keep;
    // The cover's erosion at the half step: tau_b dt / rho per horizontal area is Coulomb's impulse
    // plus Voellmy's drag g |u|^2 / xi per bed area (gxd = dt g / xi) over c.
    const double tau_dt = imp + gxd * up * up / c;
    ent = ground_entrainment(k.ground, tau_dt, up, Hp * c, cov);
    sp = ent > 0 ? sp * H / (H + ent) : sp;  // taken up at rest: the momentum is kept
    H = H + ent;
    inv = 1.0 / H;
  }
  const bool wet = H > k.dry;
  return NewState{H,   wet ? MU : 0.0, wet ? MV : 0.0, wet ? MU * inv : 0.0, wet ? MV * inv : 0.0, wet ? sp : 0.0,
                  det, ent};
}

// A cell's terms of the hazard maps and the tile's sums from its new state: normal depth, impact
// pressure and speed of a flowing cell (else 0), kinetic energy, and the CFL rate
// (|U|/dx + |V|/dy + Ps sqrt(H), Ps the wave factor).
struct CellTerms {
  double h, pressure, ke, speed, rate;
};
RUNOUT_KERNEL CellTerms cell_terms(const NewState& s, double c, double Ps, double dx, double dy, double threshold,
                                   double density) {
  const double h = s.H * c, sp2 = s.sp * s.sp;
  const bool flowing = h > threshold;
  return CellTerms{h, flowing ? density * sp2 : 0.0, 0.5 * s.H * sp2, flowing ? s.sp : 0.0,
                   std::abs(s.U) / dx + std::abs(s.V) / dy + Ps * std::sqrt(s.H)};
}

}  // namespace runout::engine::sh2d_detail
