// The distributed mesh under `mpirun -n N` (N = 1, 2, 4; label mpi): the partition, each rank's part
// of the mesh, the halo's exchange and the gather, and a finite-volume operator on the parts that
// gives the whole mesh's values bit for bit.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <cmath>
#include <cstring>

#include "engine/vof/fv/grad.hpp"
#include "engine/vof/fv/ops.hpp"
#include "engine/vof/error.hpp"
#include "engine/vof/linear/petsc.hpp"
#include "engine/vof/mpi/mesh_part.hpp"

namespace vof = runout::engine::vof;
using V3 = vof::Vec;

namespace {

vof::Comm world() { return vof::Comm::of(PETSC_COMM_WORLD); }

// A box of 24 x 8 x 6 cells with a cylinder blocked out of it (a cut-out obstacle patch).
vof::Mesh box_with_cylinder() {
  vof::Block3Spec s;
  s.x1 = 2.4;
  s.y1 = 0.8;
  s.z1 = 0.6;
  s.nx = 24;
  s.ny = 8;
  s.nz = 6;
  s.y_grading = 2;
  s.blocked = [](const V3& c) { return std::hypot(c.x - 1.2, c.z - 0.3) < 0.15 && c.y < 0.4; };
  return vof::block_mesh_3d(s);
}

// A terrain-following mesh: 20 x 6 layers x 12 columns over a bumpy bed, its columns above the bed.
vof::Mesh bumpy_columns(vof::MeshColumns& cols) {
  vof::HexGridSpec s;
  s.ni = 20;
  s.nj = 6;
  s.nk = 12;
  s.node = [](int i, int j, int k) {
    const double x = 10.0 * i, z = 10.0 * k, bed = 5 * std::sin(0.2 * x) * std::cos(0.3 * z) - 0.5 * x;
    return V3{x, bed + 20.0 * std::pow(double(j) / 6, 1.5), z};
  };
  auto m = vof::structured_hex_mesh(s);
  const auto& bottom = m.patch("bottom");
  std::vector<int> bed;
  for (int f = bottom.start; f < bottom.start + bottom.size; ++f) bed.push_back(f);
  cols = vof::columns_above(m, bed);
  return m;
}

// A value per cell of the whole mesh that no two cells share.
double tag(int c) { return std::sin(0.37 * c) + 1e-3 * c; }

// The same bytes on every rank (the partition is computed by each rank alone).
bool same_on_every_rank(const std::vector<int>& v) {
  const auto w = world();
  std::vector<int> root = v;
  MPI_Bcast(root.data(), int(root.size()), MPI_INT, 0, w.comm);
  return !w.any(root != v);
}

}  // namespace

TEST(Partition, EveryRankGetsCellsAndEveryRankTheSameSplit) {
  const auto w = world();
  const auto m = box_with_cylinder();
  const auto p = vof::partition_cells(m, {}, w.size);
  ASSERT_EQ(p.part.size(), std::size_t(m.cells()));
  EXPECT_TRUE(same_on_every_rank(p.part));
  EXPECT_EQ(vof::partition_cells(m, {}, w.size).part, p.part) << "the same mesh split twice";
  EXPECT_LT(p.imbalance, 1.1);
  if (w.size == 1) {
    EXPECT_EQ(p.cut_faces, 0);
  }
  if (w.root())
    std::printf("%d ranks: %d cells, %lld of %d internal faces cut, imbalance %.3f\n", w.size, m.cells(), p.cut_faces, m.n_internal,
                p.imbalance);
}

TEST(Partition, AColumnMeshIsSplitByWholeColumns) {
  const auto w = world();
  vof::MeshColumns cols;
  const auto m = bumpy_columns(cols);
  const auto p = vof::partition_cells(m, cols, w.size);
  EXPECT_TRUE(same_on_every_rank(p.part));
  for (int k = 0; k < cols.columns(); ++k)
    for (int i = cols.start[k]; i < cols.start[k + 1]; ++i) ASSERT_EQ(p.part[cols.cells[i]], p.part[cols.cells[cols.start[k]]]) << "column " << k;
  EXPECT_LT(p.imbalance, 1.1);
  const auto part = vof::mesh_part(m, p, w.rank, cols);
  int whole = 0;
  for (int k = 0; k < cols.columns(); ++k) whole += p.part[cols.cells[cols.start[k]]] == w.rank;
  EXPECT_EQ(part.columns.columns(), whole);
  EXPECT_NO_THROW(vof::check_columns(part.mesh, part.columns));
  EXPECT_THROW(vof::partition_cells(m, cols, cols.columns() + 1), vof::VofError);
}

// Under gravity, a mesh that spreads across the flow is cut into strips along it (here along x, the
// longer side): every rank's columns lie side by side across z, and each rank holds a whole band.
TEST(Partition, AMeshSpreadAcrossTheFlowIsCutIntoStripsAlongIt) {
  const auto w = world();
  vof::MeshColumns cols;
  const auto m = bumpy_columns(cols);
  const auto p = vof::partition_cells(m, cols, w.size, V3{0, -9.81, 0});
  if (w.size == 1) return;
  EXPECT_TRUE(p.strips);
  EXPECT_NEAR(std::abs(p.across.z), 1.0, 1e-9);
  EXPECT_LT(p.imbalance, 1.1);
  std::vector<double> lo(w.size, 1e300), hi(w.size, -1e300);
  for (int c = 0; c < m.cells(); ++c) {
    lo[p.part[c]] = std::min(lo[p.part[c]], m.centre[c].z);
    hi[p.part[c]] = std::max(hi[p.part[c]], m.centre[c].z);
  }
  for (int r = 0; r + 1 < w.size; ++r) EXPECT_LT(hi[r], lo[r + 1]) << "the bands overlap";
  EXPECT_TRUE(same_on_every_rank(p.part));
}

// Each own cell of a part has the whole mesh's faces in the whole mesh's order, with the same
// geometry; the parts' own cells are the whole mesh once.
TEST(MeshPart, OwnCellsKeepTheirFacesInTheWholeMeshsOrder) {
  const auto w = world();
  const auto m = box_with_cylinder();
  const auto p = vof::partition_cells(m, {}, w.size);
  const auto part = vof::mesh_part(m, p, w.rank, {});
  EXPECT_EQ(w.sum((long long)part.owned), (long long)m.cells());
  ASSERT_EQ(part.mesh.patches.size(), m.patches.size() + 1);
  EXPECT_EQ(part.mesh.patches.back().name, vof::kRankRim);
  if (w.size == 1) {
    EXPECT_EQ(part.mesh.patches.back().size, 0);
  }
  vof::CellFaces gf, lf;
  gf.build(m);
  lf.build(part.mesh);
  for (int c = 0; c < part.owned; ++c) {
    const int g = part.cell_global[c];
    const auto a = gf[g], b = lf[c];
    ASSERT_EQ(a.size(), b.size()) << "cell " << g;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const int f = b[i];
      ASSERT_EQ(part.face_global[f], a[i]) << "cell " << g;
      EXPECT_EQ(std::memcmp(&part.mesh.Sf[f], &m.Sf[a[i]], sizeof(V3)), 0);
      EXPECT_EQ(part.mesh.delta_coeff[f], m.delta_coeff[a[i]]);
      EXPECT_EQ(part.mesh.weight[f], m.weight[a[i]]);
      if (f >= part.mesh.n_internal) {  // a boundary face keeps its patch
        ASSERT_LT(f, part.mesh.patches.back().start);
        int pi = 0;
        while (f >= part.mesh.patches[pi].start + part.mesh.patches[pi].size) ++pi;
        EXPECT_GE(a[i], m.patches[pi].start);
        EXPECT_LT(a[i], m.patches[pi].start + m.patches[pi].size);
      }
    }
  }
}

// The exchange gives every ghost its owner's value; the gather gives every rank the whole field.
TEST(Halo, GhostsTakeTheirOwnersValuesAndTheGatherTheWholeField) {
  const auto w = world();
  const auto m = box_with_cylinder();
  const auto part = vof::mesh_part(m, vof::partition_cells(m, {}, w.size), w.rank, {});
  const vof::Halo halo(w, part.halo, part.owned_cells);
  std::vector<double> a(part.mesh.cells(), -1e300);
  std::vector<V3> u(part.mesh.cells(), V3{-1, -1, -1});
  for (int c = 0; c < part.owned; ++c) {
    a[c] = tag(part.cell_global[c]);
    u[c] = V3{tag(part.cell_global[c]), 2.0 * part.cell_global[c], -1.0};
  }
  halo.exchange(a);
  halo.exchange(u);
  for (int c = part.owned; c < part.mesh.cells(); ++c) {
    EXPECT_EQ(a[c], tag(part.cell_global[c]));
    EXPECT_EQ(u[c].y, 2.0 * part.cell_global[c]);
  }
  std::vector<double> whole;
  halo.gather(a, whole);
  ASSERT_EQ(whole.size(), std::size_t(m.cells()));
  for (int c = 0; c < m.cells(); ++c) EXPECT_EQ(whole[c], tag(c));
  EXPECT_EQ(w.sum(halo.bytes_per_exchange(8)), 8 * w.sum((long long)part.ghosts())) << "what is sent is what the ghosts receive";
}

// Two operators in a row, the second reading the first's values across the ranks' boundary: the
// Gauss gradient of a field, exchanged, then the divergence of its interpolation. On the parts'
// own cells both are the whole mesh's, bit for bit, for any number of ranks.
TEST(Halo, AnOperatorOnThePartsIsTheWholeMeshsBitForBit) {
  const auto w = world();
  vof::MeshColumns cols;
  const auto m = bumpy_columns(cols);
  const auto part = vof::mesh_part(m, vof::partition_cells(m, cols, w.size), w.rank, cols);
  const vof::Halo halo(w, part.halo, part.owned_cells);
  auto run = [](const vof::Mesh& mesh, vof::CellField<double> x, const std::function<void(vof::CellField<V3>&)>& sync) {
    vof::CellFaces cf;
    cf.build(mesh);
    std::vector<int> all(mesh.cells());
    for (int c = 0; c < mesh.cells(); ++c) all[c] = c;
    vof::CellField<V3> g(mesh.cells());
    vof::grad(mesh, cf, all, [&](int f, int c) { return vof::internal(mesh, f) ? vof::interpolate(mesh, f, x) : x[c]; }, g);
    sync(g);
    vof::CellField<double> div(mesh.cells(), 0.0);
    for (int c = 0; c < mesh.cells(); ++c)
      for (int f : cf[c]) {
        const V3 gf = vof::internal(mesh, f) ? vof::interpolate(mesh, f, g) : g[c];
        const double flux = vof::dot(gf, mesh.Sf[f]);
        div[c] += mesh.owner[f] == c ? flux : -flux;
      }
    return div;
  };
  vof::CellField<double> xg(m.cells()), xl(part.mesh.cells());
  for (int c = 0; c < m.cells(); ++c) xg[c] = tag(c) * m.centre[c].x;
  for (int c = 0; c < part.mesh.cells(); ++c) xl[c] = xg[part.cell_global[c]];
  const auto whole = run(m, xg, [](vof::CellField<V3>&) {});
  const auto parted = run(part.mesh, xl, [&](vof::CellField<V3>& g) { halo.exchange(g); });
  int differ = 0;
  for (int c = 0; c < part.owned; ++c) differ += std::memcmp(&parted[c], &whole[part.cell_global[c]], sizeof(double)) != 0;
  EXPECT_EQ(differ, 0);
  if (w.size > 1) {  // without the exchange, the cells next to the ranks' boundary differ
    const auto unsynced = run(part.mesh, xl, [](vof::CellField<V3>&) {});
    int wrong = 0;
    for (int c = 0; c < part.owned; ++c) wrong += unsynced[c] != whole[part.cell_global[c]];
    EXPECT_GT(w.sum((long long)wrong), 0);
  }
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  vof::petsc_init();
  // Every rank runs every test and prints its own report; the program fails when any rank's test did.
  const int rc = RUN_ALL_TESTS();
  const int any = world().any(rc != 0) ? 1 : 0;
  PetscFinalize();
  return any;
}
