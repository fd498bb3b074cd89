// The terrain-following column mesh of the 3D engine on terrain: layer levels, the ground at the
// nodes (exact on a plane DEM, whatever its orientation to the grid), the engine's mesh of the kept
// columns (volume, patches, closed cells) and its quality on a slope.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "engine/vof/mesh_quality.hpp"
#include "jobs/drivers/vof_terrain/corridor.hpp"
#include "jobs/drivers/vof_terrain/mesh.hpp"
#include "jobs/drivers/vof_terrain/release.hpp"
#include "jobs/drivers/vof_terrain/setup.hpp"
#include "terrain/column_mesh.hpp"

namespace {

using runout::terrain::ColumnMeshSpec;
using runout::terrain::Grid;
namespace vt = runout::jobs::vof_terrain;

constexpr double kPi = 3.14159265358979323846;

// A plane falling at `slope_deg` towards the azimuth `turn_deg` (0: east, counter-clockwise), on a
// grid of nx x ny cells of dx; the cells for which `out` holds lie outside the domain.
template <class Out>
Grid plane(int nx, int ny, double dx, double slope_deg, double turn_deg, Out out) {
  Grid g;
  g.nx = nx;
  g.ny = ny;
  g.dx = dx;
  g.x_min = 600000;
  g.y_min = 5100000;
  g.z.resize(g.cells());
  g.outside.resize(g.cells());
  const double t = std::tan(slope_deg * kPi / 180), a = turn_deg * kPi / 180;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = (i + 0.5) * dx, y = (j + 0.5) * dx;
      g.z[std::size_t(j) * nx + i] = 2000 - t * (x * std::cos(a) + y * std::sin(a));
      g.outside[std::size_t(j) * nx + i] = out(i, j) ? 1 : 0;
    }
  return g;
}

}  // namespace

TEST(ColumnMesh, LayersGrowTowardsTheBandHeight) {
  const auto l = runout::terrain::layer_levels({0.5, 1.2, 10});
  ASSERT_GE(l.size(), 3u);
  EXPECT_EQ(l.front(), 0.0);
  EXPECT_EQ(l.back(), 10.0);
  EXPECT_LE(l[1], 0.5);
  EXPECT_GT(l[1], 0.5 / 1.2);
  for (std::size_t k = 2; k < l.size(); ++k) EXPECT_NEAR((l[k] - l[k - 1]) / (l[k - 1] - l[k - 2]), 1.2, 1e-12);
  EXPECT_EQ(runout::terrain::layer_levels({1, 1, 4}).size(), 5u);  // uniform layers
}

TEST(ColumnMesh, BadOptionsAreNamed) {
  auto message = [](ColumnMeshSpec s) {
    try {
      runout::terrain::layer_levels(s);
    } catch (const runout::terrain::TerrainError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({0, 1.2, 10}).find("mesh.first_layer_m"), std::string::npos);
  EXPECT_NE(message({0.5, 0.9, 10}).find("mesh.growth"), std::string::npos);
  EXPECT_NE(message({0.5, 1.2, 0.2}).find("mesh.band_height_m"), std::string::npos);
}

TEST(ColumnMesh, GroundNodesLieOnAPlaneDemAtAnyOrientation) {
  for (double turn : {0.0, 30.0, 45.0, 200.0}) {
    const Grid g = plane(12, 9, 10, 35, turn, [](int, int) { return false; });
    const auto c = runout::terrain::column_mesh(g, {0.5, 1.2, 8});
    const double t = std::tan(35 * kPi / 180), a = turn * kPi / 180;
    for (int k = 0; k <= c.nk; ++k)
      for (int i = 0; i <= c.ni; ++i) {
        const double x = i * g.dx, y = k * g.dx;
        EXPECT_NEAR(c.ground_at(i, k), 2000 - t * (x * std::cos(a) + y * std::sin(a)), 1e-9) << "turn " << turn;
      }
    EXPECT_EQ(c.kept_columns(), 12 * 9);
  }
}

TEST(ColumnMesh, EngineMeshOfTheKeptColumnsOnASlope) {
  // A 30 deg slope turned by 30 deg against the grid; a corner of 3 x 2 columns outside the domain.
  const double slope = 30;
  const Grid g = plane(10, 8, 5, slope, 30, [](int i, int j) { return i >= 7 && j >= 6; });
  const auto c = runout::terrain::column_mesh(g, {0.4, 1.25, 6});
  const auto frame = vt::frame_of(c);
  const auto m = vt::terrain_mesh(c, frame);
  const int kept = 10 * 8 - 3 * 2;
  EXPECT_EQ(c.kept_columns(), kept);
  EXPECT_EQ(m.cells(), kept * c.layers());
  // Vertical columns between two parallel surfaces: each holds dx^2 times the band height.
  double volume = 0;
  for (double v : m.volume) volume += v;
  EXPECT_NEAR(volume, kept * 25.0 * 6, 1e-9 * kept * 25.0 * 6);
  // The ground's area is the columns' plan area over cos(slope); it faces down.
  const auto& ground = m.patch("ground");
  double area = 0, up = 0;
  for (int f = ground.start; f < ground.start + ground.size; ++f) {
    area += m.magSf[f];
    up += m.Sf[f].y;
  }
  EXPECT_EQ(ground.size, kept);
  EXPECT_NEAR(area, kept * 25.0 / std::cos(slope * kPi / 180), 1e-9 * area);
  EXPECT_NEAR(up, -kept * 25.0, 1e-9 * kept * 25.0);
  EXPECT_EQ(m.patch("atmosphere").size, kept);
  // Sides: the grid's edges and the cut-out corner's two inner edges, every layer.
  EXPECT_EQ(m.patch("sides").size, (2 * 10 + 2 * 8) * c.layers());
  // The frame: y up from the lowest ground node, x east and z south from the grid's centre; the
  // lowest cell centre lies in the first layer (0.4 m at most) above the lowest kept column's ground
  // (the mean of its four ground nodes).
  double ymin = 1e300, ground_min = 1e300;
  for (int k = 0; k < m.cells(); ++k) ymin = std::min(ymin, m.centre[k].y);
  for (int k = 0; k < c.nk; ++k)
    for (int i = 0; i < c.ni; ++i)
      if (c.kept[std::size_t(k) * c.ni + i])
        ground_min = std::min(ground_min, 0.25 * (c.ground_at(i, k) + c.ground_at(i + 1, k) + c.ground_at(i, k + 1) +
                                                  c.ground_at(i + 1, k + 1)) - frame.z);
  EXPECT_GE(ground_min, 0.0);
  EXPECT_GT(ymin, ground_min);
  EXPECT_LT(ymin, ground_min + 0.4);
  EXPECT_NEAR(frame.x, g.x_min + 25, 1e-9);
  EXPECT_NEAR(frame.y, g.y_min + 20, 1e-9);
  // Non-orthogonality: the layers follow the 30 deg slope over vertical columns.
  const auto q = runout::engine::vof::mesh_quality(m);
  EXPECT_NEAR(q.non_orthogonality_max_deg, slope, 1e-6);
  EXPECT_GT(q.non_orthogonality_mean_deg, 5.0);
  EXPECT_LT(q.skewness_max, 0.5);
  EXPECT_GT(q.aspect_ratio_max, 5 / 0.4 * 0.5);  // the thin first layer
}

// Refined columns (mesh.refinement R): R x R columns per grid cell on the unrefined mesh's ground
// (the refined nodes that are grid corners carry the same elevation, the others lie on the bilinear
// patches between them), the same kept cells, mesh volume, ground area and release volume; the
// release's alpha the same in every column of a cell; the grid cell and sub-column numbering
// inverse to each other.
TEST(ColumnMesh, RefinedColumnsLieOnTheSameGround) {
  // A curved ground (a bowl) with a corner outside the domain, so that the bilinear patches matter.
  Grid g = plane(10, 8, 5, 20, 30, [](int i, int j) { return i >= 7 && j >= 6; });
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) g.z[std::size_t(j) * g.nx + i] += 0.02 * ((i - 4.5) * (i - 4.5) + (j - 3.5) * (j - 3.5)) * 25;
  std::vector<double> H(g.cells(), 0.0);
  for (int j = 2; j < 5; ++j)
    for (int i = 2; i < 6; ++i) H[std::size_t(j) * g.nx + i] = 1.0 + 0.1 * i;
  const ColumnMeshSpec one{0.3, 1.2, 6};
  const auto c1 = runout::terrain::column_mesh(g, one);
  const auto m1 = vt::terrain_mesh(c1, vt::frame_of(c1));
  const auto a1 = vt::release_alpha(c1, H);
  auto sums = [](const runout::engine::vof::Mesh& m, const std::vector<double>& a) {
    double v = 0, va = 0, ground = 0;
    for (int k = 0; k < m.cells(); ++k) {
      v += m.volume[std::size_t(k)];
      va += a[std::size_t(k)] * m.volume[std::size_t(k)];
    }
    const auto& p = m.patch("ground");
    for (int f = p.start; f < p.start + p.size; ++f) ground += m.magSf[std::size_t(f)];
    return std::vector<double>{v, va, ground};
  };
  const auto s1 = sums(m1, a1);
  for (int r : {2, 4}) {
    ColumnMeshSpec spec = one;
    spec.refinement = r;
    const auto c = runout::terrain::column_mesh(g, spec);
    EXPECT_EQ(c.ni, g.nx * r);
    EXPECT_EQ(c.nk, g.ny * r);
    EXPECT_DOUBLE_EQ(c.dx, g.dx / r);
    EXPECT_EQ(c.kept_columns(), r * r * c1.kept_columns());
    for (int k = 0; k <= g.ny; ++k)
      for (int i = 0; i <= g.nx; ++i) EXPECT_NEAR(c.ground_at(i * r, k * r), c1.ground_at(i, k), 1e-9);
    const auto m = vt::terrain_mesh(c, vt::frame_of(c));
    const auto a = vt::release_alpha(c, H);
    const auto s = sums(m, a);
    EXPECT_NEAR(s[0], s1[0], 1e-9 * s1[0]) << "mesh volume, refinement " << r;
    EXPECT_NEAR(s[1], s1[1], 1e-9 * s1[1]) << "release volume, refinement " << r;
    EXPECT_NEAR(s[2], s1[2], 2e-3 * s1[2]) << "ground area, refinement " << r;  // the bilinear patches' area, finer sums
    const auto cols = vt::columns_of(c);
    EXPECT_EQ(cols.grid_cells(), g.cells());
    for (std::size_t gc = 0; gc < g.cells(); ++gc)
      for (int q = 0; q < r * r; ++q) {
        const std::size_t col = cols.sub_column(gc, q);
        ASSERT_EQ(cols.grid_cell(col), gc);
        ASSERT_EQ(c.grid_cell(col), gc);
        ASSERT_EQ(c.kept[col], c1.kept[gc]);
        if (c.kept[col])
          for (int j = 0; j < c.layers(); ++j) ASSERT_EQ(a[std::size_t(cols.cell(col, j))], a1[std::size_t(vt::columns_of(c1).cell(gc, j))]);
      }
  }
  ColumnMeshSpec bad = one;
  bad.refinement = 9;
  try {
    runout::terrain::column_mesh(g, bad);
    ADD_FAILURE() << "refinement 9 accepted";
  } catch (const runout::terrain::TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh.refinement"), std::string::npos) << e.what();
  }
}

// The rule of mesh.refinement 0: the smallest of 1, 2, 4 whose columns lie within ten times the
// thickest release column, halved while the mesh would exceed 250,000 cells; an asked refinement
// is taken as it is. The reason names the figures.
TEST(ColumnMesh, RefinementRule) {
  std::string why;
  EXPECT_EQ(vt::choose_refinement(3, 30, 1.8, 5314, 13, why), 3);
  EXPECT_EQ(why, "mesh.refinement 3");
  EXPECT_EQ(vt::choose_refinement(0, 10, 2.0, 1000, 13, why), 1);   // 10 m within 20 m
  EXPECT_EQ(vt::choose_refinement(0, 30, 1.8, 1000, 13, why), 2);   // 15 m within 18 m
  EXPECT_EQ(vt::choose_refinement(0, 50, 1.9, 1000, 13, why), 4);   // 12.5 m within 19 m
  EXPECT_EQ(vt::choose_refinement(0, 90, 1.8, 1000, 13, why), 4);   // at most 4
  EXPECT_EQ(vt::choose_refinement(0, 30, 1.8, 5314, 13, why), 1);   // 276,328 cells at 2
  EXPECT_NE(why.find("need 2"), std::string::npos) << why;
  EXPECT_NE(why.find("exceed 250000 cells, so 1"), std::string::npos) << why;
  EXPECT_EQ(vt::choose_refinement(0, 50, 1.9, 1357, 13, why), 2);   // 282,256 cells at 4, 70,564 at 2
}

// The release on the terrain mesh holds the depth-averaged engine's volume (its H, the vertical
// thickness, per column), alpha within [0, 1], and spans several layers with the default mesh.
TEST(TerrainRelease, VolumeIsTheDepthAveragedEnginesAndAlphaIsBounded) {
  const Grid g = plane(10, 8, 5, 30, 30, [](int i, int j) { return i >= 7 && j >= 6; });
  runout::engine::Terrain2D t;
  t.nx = g.nx;
  t.ny = g.ny;
  t.dx = t.dy = g.dx;
  t.z = g.z;
  t.outside = g.outside;
  std::vector<double> h(g.cells(), 0.0);  // 1.5 m normal to the slope in a block of 4 x 3 columns
  for (int j = 2; j < 5; ++j)
    for (int i = 2; i < 6; ++i) h[std::size_t(j) * g.nx + i] = 1.5;
  const auto H = runout::engine::state_from_normal_depth(t, h).H;
  double volume_2d = 0, h_max = 0;
  for (double v : H) {
    volume_2d += v * g.dx * g.dx;
    h_max = std::max(h_max, v);
  }
  const auto spec = vt::default_column_mesh(h_max);
  const auto c = runout::terrain::column_mesh(g, spec);
  const auto m = vt::terrain_mesh(c, vt::frame_of(c));
  const auto alpha = vt::release_alpha(c, H);
  ASSERT_EQ(alpha.size(), std::size_t(m.cells()));
  double volume_3d = 0;
  for (int k = 0; k < m.cells(); ++k) {
    EXPECT_GE(alpha[k], 0.0);
    EXPECT_LE(alpha[k], 1.0);
    volume_3d += alpha[k] * m.volume[k];
  }
  EXPECT_NEAR(volume_3d, volume_2d, 1e-12 * volume_2d);
  // Column (3, 3): kept columns are numbered i fastest, then the layer, then k.
  int filled = 0;
  for (int j = 0; j < c.layers(); ++j) {
    int q = 0;  // kept columns before row k = 3 in layers below, then in this layer
    q += 3 * c.layers() * 10;  // rows 0-2 are whole (the cut-out corner lies in rows 6-7)
    q += j * 10 + 3;
    filled += alpha[std::size_t(q)] > 0;
  }
  EXPECT_GE(filled, 4);
  EXPECT_EQ(alpha[std::size_t(3 * c.layers() * 10 + 3)], 1.0);                        // full on the ground
  EXPECT_EQ(alpha[std::size_t(3 * c.layers() * 10 + (c.layers() - 1) * 10 + 3)], 0.0);  // air at the top
  // Material outside the domain, and a band that cannot hold the release, are named.
  auto message = [&](const runout::terrain::ColumnMesh& mesh, const std::vector<double>& v) {
    try {
      vt::release_alpha(mesh, v);
    } catch (const runout::terrain::TerrainError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  auto outside = H;
  outside[std::size_t(7) * g.nx + 9] = 1.0;
  EXPECT_NE(message(c, outside).find("outside the domain"), std::string::npos);
  const auto low = runout::terrain::column_mesh(g, {0.2, 1.2, 1.0});
  EXPECT_NE(message(low, H).find("mesh.band_height_m"), std::string::npos);
}

// The columns the bed friction on the column's weight takes (vt::bed_columns): every kept column
// once, from its "ground" face up through its layers, and the bed's curvature such that u.K.u is the
// bed-normal acceleration of material moving along it: zero on a plane; on a trough
// z = y^2 / (2 R) running east, 1 / R for material moving north across its floor and 0 for
// material moving east along it.
TEST(ColumnMesh, BedColumnsCarryTheirCellsAndTheBedsCurvature) {
  Grid g = plane(12, 10, 10, 30, 20, [](int i, int j) { return i == 0 && j == 0; });
  const auto spec = vt::default_column_mesh(2.0);
  auto cm = runout::terrain::column_mesh(g, spec);
  auto m = vt::terrain_mesh(cm, vt::frame_of(cm));
  auto cols = vt::columns_of(cm);
  auto bc = vt::bed_columns(cols, m, g);
  ASSERT_EQ(bc.columns(), cm.kept_columns());
  EXPECT_EQ(int(bc.cells.size()), m.cells());
  const auto& ground = m.patch("ground");
  for (int k = 0; k < bc.columns(); ++k) {
    const int f = bc.bed_face[std::size_t(k)];
    EXPECT_GE(f, ground.start);
    EXPECT_LT(f, ground.start + ground.size);
    EXPECT_EQ(m.owner[std::size_t(f)], bc.cells[std::size_t(bc.start[std::size_t(k)])]);
    EXPECT_EQ(bc.start[std::size_t(k) + 1] - bc.start[std::size_t(k)], cols.layers);
    for (const auto& row : bc.curvature[std::size_t(k)].g)
      for (double v : row) EXPECT_NEAR(v, 0.0, 1e-12);
  }
  const double R = 500;
  g = plane(12, 10, 10, 0, 0, [](int, int) { return false; });
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double y = (j + 0.5 - 0.5 * g.ny) * g.dx;
      g.z[std::size_t(j) * g.nx + i] = 2000 + y * y / (2 * R);
    }
  cm = runout::terrain::column_mesh(g, spec);
  m = vt::terrain_mesh(cm, vt::frame_of(cm));
  bc = vt::bed_columns(vt::columns_of(cm), m, g);
  const auto& K = bc.curvature[std::size_t(5 * g.nx + 6)];  // next to the trough's floor (y = 5 m)
  const runout::engine::vof::Vec north{0, 0, -1}, east{1, 0, 0};
  auto uKu = [&](const runout::engine::vof::Vec& u) {
    double s = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s += runout::engine::vof::comp(u, i) * K.g[i][j] * runout::engine::vof::comp(u, j);
    return s;
  };
  EXPECT_NEAR(uKu(north), 1 / R, 1e-3 / R);  // cos(theta) = 0.99995 there
  EXPECT_NEAR(uKu(east), 0.0, 1e-12);
}

// The footprint corridor (mesh.corridor "footprint"): the cells above the flow threshold and the
// release's, dilated by the margin (centre to centre), intersected with the domain; the faces towards
// a domain column left out are the corridor's edge, those at the grid's or the domain's edge are not.
TEST(ColumnMesh, CorridorFromAFootprintKeepsTheMarginsColumns) {
  // 24 x 20 cells of 10 m; the domain leaves out the columns i >= 20 (the east edge).
  const Grid g = plane(24, 20, 10, 20, 0, [](int i, int) { return i >= 20; });
  std::vector<double> max_depth(g.cells(), 0.0), h0(g.cells(), 0.0);
  auto at = [&](int i, int j) { return std::size_t(j) * g.nx + i; };
  for (int i = 8; i <= 17; ++i) max_depth[at(i, 10)] = 0.5;  // a path along row 10
  max_depth[at(12, 11)] = 0.005;                            // below the threshold
  h0[at(3, 3)] = 1.5;                                       // the release, off the path
  const double margin = 25;                                 // 2.5 cells
  int footprint = 0;
  const auto corridor = vt::footprint_corridor(g, max_depth, 0.01, h0, margin, &footprint);
  EXPECT_EQ(footprint, 11);
  // Every cell whose centre lies within 25 m of a footprint cell's centre, and no other.
  int expected = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      bool near = false;
      for (int jj = 0; jj < g.ny; ++jj)
        for (int ii = 0; ii < g.nx; ++ii)
          if ((max_depth[at(ii, jj)] > 0.01 || h0[at(ii, jj)] > 0) && std::hypot(ii - i, jj - j) * g.dx <= margin + 1e-9) near = true;
      EXPECT_EQ(corridor[at(i, j)] != 0, near) << i << ", " << j;
      expected += near && i < 20;
    }
  // The path's disc around (17, 10) reaches i = 19; the release's disc is 21 cells (radius 2.5).
  EXPECT_TRUE(corridor[at(19, 10)]);
  EXPECT_FALSE(corridor[at(20, 10)]);
  EXPECT_TRUE(corridor[at(5, 4)]);   // 22.4 m from the release
  EXPECT_FALSE(corridor[at(5, 5)]);  // 28.3 m
  const auto c = runout::terrain::column_mesh(g, {0.4, 1.25, 6}, corridor);
  EXPECT_EQ(c.kept_columns(), expected);
  // The corridor's edge: faces of kept columns towards domain columns that are not kept.
  const auto m = vt::terrain_mesh(c, vt::frame_of(c));
  const auto cols = vt::columns_of(c);
  const auto edge = vt::corridor_edge_faces(cols, m, g);
  int edge_faces = 0, expected_faces = 0;
  for (auto e : edge) edge_faces += e;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      if (!c.kept[at(i, j)]) continue;
      const int nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
      for (const auto& n : nb)
        if (n[0] >= 0 && n[1] >= 0 && n[0] < g.nx && n[1] < g.ny && !g.outside[at(n[0], n[1])] && !c.kept[at(n[0], n[1])])
          expected_faces += c.layers();
    }
  EXPECT_EQ(edge_faces, expected_faces);
  EXPECT_GT(edge_faces, 0);
  // Refined columns (mesh.refinement 2): the same corridor's edge, each face split in two.
  ColumnMeshSpec refined{0.4, 1.25, 6};
  refined.refinement = 2;
  const auto c2 = runout::terrain::column_mesh(g, refined, corridor);
  const auto m2 = vt::terrain_mesh(c2, vt::frame_of(c2));
  const auto edge2 = vt::corridor_edge_faces(vt::columns_of(c2), m2, g);
  int edge2_faces = 0;
  for (auto e : edge2) edge2_faces += e;
  EXPECT_EQ(edge2_faces, 2 * edge_faces);
  // Every flagged face is a side face; the path's column at i = 19 faces the domain's edge (i = 20), unflagged.
  const auto& sides = m.patch("sides");
  for (int f = 0; f < m.faces(); ++f)
    if (edge[std::size_t(f)]) EXPECT_TRUE(f >= sides.start && f < sides.start + sides.size);
  // The default margin: 150 m, or two cells on a coarser grid; a given one as given.
  runout::v1::TerrainMesh tm;
  EXPECT_EQ(vt::corridor_margin(tm, 30), 150);
  EXPECT_EQ(vt::corridor_margin(tm, 90), 180);
  tm.set_corridor_margin_m(40);
  EXPECT_EQ(vt::corridor_margin(tm, 90), 40);
  // No margin: the footprint itself.
  const auto bare = runout::terrain::dilate_cells(g, corridor, 0);
  EXPECT_EQ(bare, corridor);
}
