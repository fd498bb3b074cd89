// The VOF engine's finite-volume vocabulary and registries: fields, FvMatrix's A(), H(), H1() and
// flux(), the mixture formulas, the granular viscosity and the boundary conditions by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "engine/vof/fv/fv_matrix.hpp"
#include "engine/vof/fv/ops.hpp"
#include "engine/vof/mixture.hpp"
#include "engine/vof/models/registry.hpp"
#include "engine/vof/models/mu_i_law.hpp"
#include "engine/vof/solver.hpp"

using namespace runout::engine::vof;

namespace {

Mesh row_of_cells(int n) {
  BlockSpec b;
  b.x1 = n * 0.1;
  b.y1 = 0.1;
  b.nx = n;
  b.ny = 1;
  b.thickness = 0.1;
  return block_mesh(b);
}

std::vector<int> all(int n) {
  std::vector<int> v(std::size_t(n), 0);
  for (int k = 0; k < n; ++k) v[std::size_t(k)] = k;
  return v;
}

VofConfig walls_and_top(Bc top) {
  VofConfig c;
  for (const char* p : {"bottom", "left", "right"}) c.bc[p].kind = Bc::wall;
  c.bc["top"].kind = top;
  return c;
}

}  // namespace

TEST(VofFv, FieldsIndexWithInts) {
  CellField<double> a(3, 1.5);
  const int k = 2;
  a[k] = 4;
  EXPECT_EQ(a[2], 4);
  const std::vector<double>& v = a;  // a field is a vector
  EXPECT_EQ(v.size(), 3u);
}

TEST(VofFv, MatrixHAndFlux) {
  const Mesh m = row_of_cells(3);  // two internal faces: 0-1 and 1-2
  ASSERT_EQ(m.n_internal, 2);
  FvMatrix<double> M;
  M.resize(m.cells(), m.faces());
  for (int c = 0; c < 3; ++c) {
    M.diag[c] = 10 + c;
    M.source[c] = c;
  }
  for (int f = 0; f < m.n_internal; ++f) {
    M.upper[f] = 2 + f;
    M.lower[f] = 3 + f;
  }
  CellField<double> psi(3, 0.0);
  psi[0] = 1;
  psi[1] = 10;
  psi[2] = 100;
  const auto cells = all(3), faces = all(m.faces());
  CellField<double> H(3, 0.0), H1(3, 0.0);
  CellFaces cf;
  cf.build(m);
  const std::vector<char> face_in(std::size_t(m.faces()), 1);
  M.H(m, cf, face_in, psi, cells, H);
  M.H1(m, cf, face_in, cells, H1);
  EXPECT_EQ(M.A()[1], 11);
  // Face f joins owner o and neighbour n: H_o += upper psi_n, H_n += lower psi_o.
  std::vector<double> want = {0, 1, 2}, want1 = {0, 0, 0};
  for (int f = 0; f < m.n_internal; ++f) {
    const int o = m.owner[f], n = m.neighbour[f];
    want[std::size_t(o)] += M.upper[f] * psi[n];
    want[std::size_t(n)] += M.lower[f] * psi[o];
    want1[std::size_t(o)] += M.upper[f];
    want1[std::size_t(n)] += M.lower[f];
    EXPECT_EQ(M.flux(m, f, psi), -M.upper[f] * (psi[n] - psi[o]));
  }
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(H[c], want[std::size_t(c)]);
    EXPECT_EQ(H1[c], want1[std::size_t(c)]);
  }
  EXPECT_EQ(M.flux_out(0, 2.0, 5.0), -M.upper[0] * 3.0);
}

TEST(VofFv, InterpolateAndReconstruct) {
  const Mesh m = row_of_cells(3);
  CellField<double> x(3, 0.0);
  x[0] = 1;
  x[1] = 3;
  x[2] = 5;
  for (int f = 0; f < m.n_internal; ++f) EXPECT_NEAR(interpolate(m, f, x), 0.5 * (x[m.owner[f]] + x[m.neighbour[f]]), 1e-14);
  // A uniform vector's face values q = U.Sf / |Sf| reconstruct it exactly.
  CellFaces cf;
  cf.build(m);
  Reconstruction rec;
  rec.build(m, cf, 2);
  const Vec U{0.3, -1.2, 0};
  for (int c = 0; c < m.cells(); ++c) {
    Vec r;
    for (int f : cf[c]) r = r + (dot(U, m.Sf[f]) / m.magSf[f]) * m.Sf[f];
    const Vec got = rec(c, r);
    EXPECT_NEAR(got.x, U.x, 1e-12);
    EXPECT_NEAR(got.y, U.y, 1e-12);
  }
}

TEST(VofFv, MixtureFormulas) {
  VofConfig c;
  const Mixture mix(c);
  EXPECT_EQ(mix.rho(1), c.rho1);
  EXPECT_EQ(mix.rho(0), c.rho2);
  EXPECT_EQ(mix.rho(1.5), c.rho1);  // clipped to [0, 1]
  EXPECT_EQ(mix.mu(0.25, 2.0), 0.25 * c.rho1 * 2.0 + 0.75 * c.rho2 * c.nu2);
  EXPECT_EQ(mix.rho_flux(0.5, 2.0), 0.5 * (c.rho1 - c.rho2) + 2.0 * c.rho2);
}

TEST(VofFv, CoulombViscosityByName) {
  VofConfig c;
  c.phi_deg = 45;
  const auto nu = make_granular_viscosity(c);
  EXPECT_NEAR(nu->nu(1000, 2.0), 1000 / (c.rho1 * 2.0), 1e-12);
  EXPECT_EQ(nu->nu(1000, 0.0), c.nu_max);  // at rest: the clip
  EXPECT_EQ(nu->nu(-1000, 1.0), c.nu_min);
  EXPECT_EQ(granular_viscosity_names(), (std::vector<std::string>{"coulomb", "mu_i", "mu_i_unregularised"}));
  c.phi_deg = 90;  // the row's check, before the model is made
  try {
    (void)make_granular_viscosity(c);
    ADD_FAILURE() << "phi = 90 deg accepted";
  } catch (const VofError& e) {
    EXPECT_NE(std::string(e.what()).find("rheology coulomb: phi_deg must lie in (0, 90)"), std::string::npos) << e.what();
  }
}

// mu(I) through the viscosity: nu rho1 |strain rate| / p is mu(I) at I = d |strain rate| / sqrt(p / rho_s).
namespace {
double mu_at(const GranularViscosity& v, const VofConfig& c, double I, double p = 500) {
  const double sr = I * std::sqrt(p / c.mu_i.grain_density) / c.mu_i.grain_diameter;
  return v.nu(p, sr) * c.rho1 * sr / p;
}
}  // namespace

TEST(VofFv, MuIViscosityFollowsTheLawAndItsRegularisation) {
  VofConfig c;
  c.rho1 = 1470;
  c.rheology = "mu_i_unregularised";
  const auto raw = make_granular_viscosity(c);
  c.rheology = "mu_i";
  const auto reg = make_granular_viscosity(c);
  const auto& m = c.mu_i;
  auto law = [&](double I) { return m.mu_s + (m.mu_2 - m.mu_s) / (m.i0 / I + 1); };
  for (double I : {1e-4, 1e-2, 0.1, 0.279, 1.0, 10.0}) EXPECT_NEAR(mu_at(*raw, c, I), law(I), 1e-12 * law(I)) << I;
  EXPECT_NEAR(mu_at(*raw, c, 0.279), 0.5 * (m.mu_s + m.mu_2), 1e-12);  // halfway at I_0
  for (double I : {0.05, 0.1, 1.0}) EXPECT_NEAR(mu_at(*reg, c, I), law(I), 1e-12 * law(I)) << I;  // above I_1 = 0.0207
  // Below I_1 the regularised friction is smaller and falls towards 0; it joins the law with the
  // same value and slope at I_1.
  EXPECT_LT(mu_at(*reg, c, 1e-3), law(1e-3) - 0.02);
  EXPECT_LT(mu_at(*reg, c, 1e-12), 0.25);
  double lo = 1e-4, hi = 0.2;  // I_1: where the regularised branch starts to differ from the law
  for (int k = 0; k < 100; ++k) {
    const double mid = std::sqrt(lo * hi);
    (std::abs(mu_at(*reg, c, mid) - law(mid)) > 1e-13 ? lo : hi) = mid;
  }
  EXPECT_NEAR(hi, 0.0207, 1e-4);
  const double e = 1e-6 * hi;
  EXPECT_NEAR(mu_at(*reg, c, hi - e), mu_at(*reg, c, hi + e), 1e-6);  // continuous (the slope is about 0.8)
  const double slope_below = (mu_at(*reg, c, hi - e) - mu_at(*reg, c, hi - 3 * e)) / (2 * e);
  const double slope_above = (mu_at(*reg, c, hi + 3 * e) - mu_at(*reg, c, hi + e)) / (2 * e);
  EXPECT_NEAR(slope_below, slope_above, 1e-3 * slope_above);  // and smooth
  // No pressure, or a tension: the clip, as the Coulomb viscosity has it.
  EXPECT_EQ(reg->nu(-1000, 1.0), c.nu_min);
  EXPECT_EQ(reg->nu(1000, 0.0), c.nu_max);
}

TEST(VofFv, MuIParametersAreChecked) {
  auto bad = [](auto change, const char* expected) {
    VofConfig c;
    c.rho1 = 1470;
    c.rheology = "mu_i";
    change(c);
    try {
      make_granular_viscosity(c);
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const VofError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  bad([](VofConfig& c) { c.mu_i.mu_2 = 0.3; }, "mu_2 must be at least mu_s");
  bad([](VofConfig& c) { c.mu_i.mu_s = 0; }, "mu_s must be > 0");
  bad([](VofConfig& c) { c.mu_i.i0 = -1; }, "I_0 must be > 0");
  bad([](VofConfig& c) { c.mu_i.grain_diameter = 0; }, "grain diameter");
  bad([](VofConfig& c) { c.mu_i.grain_density = 1000; }, "grain_density_kg_m3 must be at least the material's density");
  bad([](VofConfig& c) { c.mu_i.mu_2 = c.mu_i.mu_s + 1e-3; }, "too small for alpha");
  bad([](VofConfig& c) { c.mu_i.alpha = -1; }, "alpha must be > 0");
  bad([](VofConfig& c) { c.mu_i.alpha = 1.9, c.mu_i.mu_s = 0.625, c.mu_i.mu_2 = 0.961; }, "too small for alpha");
}

// The regularisation's alpha when none is given (MuILaw::scaled_alpha): Barker & Gray's 1.9 for the
// beads; for the steeper laws of the lab materials (PVC tan 32 deg, sand tan 37 deg, each with the
// beads' rise of 11.86 deg), where 1.9 cannot join, in the same proportion to the smallest alpha
// that joins, and the law is joined with the same value and slope.
TEST(VofFv, MuIRegularisationScalesItsAlphaWithTheLaw) {
  EXPECT_EQ(MuILaw::scaled_alpha(VofConfig::MuI{}), 1.9);
  for (double repose : {32.0, 37.0}) {
    VofConfig::MuI m;
    m.mu_s = std::tan(repose * M_PI / 180), m.mu_2 = std::tan((repose + 11.86) * M_PI / 180);
    const double a = MuILaw::scaled_alpha(m);
    EXPECT_NEAR(a / MuILaw::smallest_alpha(m.mu_s, m.mu_2, m.i0), 1.9 / 0.8864, 0.01) << repose;
    const MuILaw law(m, 1600, true);
    EXPECT_EQ(law.alpha(), a);
    const double i1 = law.i1(), e = 1e-7 * i1;
    ASSERT_GT(i1, 0);
    EXPECT_NEAR(law.friction(i1 - e), law.friction(i1 + e), 1e-6) << repose;
    EXPECT_LT(law.friction(1e-6), m.mu_s) << repose;  // it creeps below mu_s
    std::printf("repose %.0f deg: alpha %.3f, I_1 %.4g, mu(1e-6) %.3f (mu_s %.3f)\n", repose, a, i1, law.friction(1e-6), m.mu_s);
  }
}

TEST(VofFv, UnknownRheologyListsTheValidNames) {
  auto c = walls_and_top(Bc::atmosphere);
  c.rheology = "bingham";
  try {
    VofSolver s(row_of_cells(4), c);
    FAIL() << "an unknown rheology was accepted";
  } catch (const VofError& e) {
    EXPECT_STREQ(e.what(), "rheology: unknown 'bingham' (valid: coulomb, mu_i, mu_i_unregularised)");
  }
}

TEST(VofFv, BoundaryConditionsByName) {
  const auto names = boundary_condition_names();
  for (const char* n : {"wall", "coulomb_slip", "atmosphere", "inflow", "outflow", "symmetry", "coulomb_friction"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  auto c = walls_and_top(Bc::atmosphere);
  c.bc["top"].type = "sky";
  try {
    VofSolver s(row_of_cells(4), c);
    FAIL() << "an unknown boundary condition was accepted";
  } catch (const VofError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("patch 'top'"), std::string::npos) << what;
    EXPECT_NE(what.find("'sky'"), std::string::npos) << what;
    EXPECT_NE(what.find("valid: wall, coulomb_slip, coulomb_friction, atmosphere"), std::string::npos) << what;
  }
}

// A condition chosen by its name is the one its Bc value chooses, bit for bit.
TEST(VofFv, ConditionByNameIsTheConditionByKind) {
  BlockSpec b;
  b.x1 = 0.1;
  b.y1 = 0.05;
  b.nx = 20;
  b.ny = 10;
  b.thickness = 0.005;
  const Mesh m = block_mesh(b);
  std::vector<double> a(std::size_t(m.cells()));
  for (int k = 0; k < m.cells(); ++k) a[std::size_t(k)] = m.centre[k].x < 0.04 && m.centre[k].y < 0.03 ? 1 : 0;
  auto by_kind = walls_and_top(Bc::atmosphere);
  by_kind.bc["left"].kind = Bc::symmetry;
  auto by_name = by_kind;
  by_name.bc["left"].kind = Bc::wall;
  by_name.bc["left"].type = "symmetry";
  VofSolver s1(m, by_kind), s2(m, by_name);
  s1.initialise(a);
  s2.initialise(a);
  for (int k = 0; k < 10; ++k) {
    s1.step();
    s2.step();
  }
  EXPECT_EQ(s1.alpha(), s2.alpha());
  EXPECT_EQ(s1.pressure(), s2.pressure());
  for (int k = 0; k < m.cells(); ++k) {
    EXPECT_EQ(s1.velocity()[std::size_t(k)].x, s2.velocity()[std::size_t(k)].x);
    EXPECT_EQ(s1.velocity()[std::size_t(k)].y, s2.velocity()[std::size_t(k)].y);
  }
}
