// The VOF engine: mesh addressing and patches of the plane block, the bent
// structured mesh and the 3D block with obstacles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "engine/vof/solver.hpp"
#include "tests/support/vof_box.hpp"

using namespace runout::engine::vof;
using namespace runout::test_support;

TEST(VofMesh, BlockMeshAddressingAndPatches) {
  Mesh m = box(4, 3);
  EXPECT_EQ(m.cells(), 12);
  EXPECT_EQ(m.n_internal, 3 * 3 + 4 * 2);
  EXPECT_EQ(m.patch("bottom").size, 4);
  EXPECT_EQ(m.patch("left").size, 3);
  for (int f = 0; f < m.n_internal; ++f) EXPECT_GT(dot(m.Sf[std::size_t(f)], m.centre[std::size_t(m.neighbour[std::size_t(f)])] - m.centre[std::size_t(m.owner[std::size_t(f)])]), 0);
  // The top beyond x = 0.1 becomes its own patch; faces stay grouped.
  split_patch(m, "top", "atmosphere", [](const Vec& c) { return c.x > 0.1; });
  EXPECT_EQ(m.patch("top").size, 2);
  EXPECT_EQ(m.patch("atmosphere").size, 2);
  for (int f = m.patch("atmosphere").start; f < m.patch("atmosphere").start + 2; ++f) EXPECT_GT(m.Cf[std::size_t(f)].x, 0.1);
}

TEST(VofMesh, BlockedCellsFormTheObstaclePatch) {
  BlockSpec b;
  b.x1 = 1;
  b.y1 = 1;
  b.nx = b.ny = 10;
  b.blocked = {{0.3, 0.0}, {0.7, 0.0}, {0.5, 0.4}};  // a ramp on the floor
  Mesh m = block_mesh(b);
  EXPECT_LT(m.cells(), 100);
  EXPECT_GT(m.patch("obstacle").size, 0);
  EXPECT_LT(m.patch("bottom").size, 10);
}

// The node-based hexahedral mesh: on a box it reproduces block_mesh_3d (cells, faces, volumes,
// centres, patches); bent along an arc it stays closed and its volume is the annulus sector's.
TEST(VofMesh, StructuredHexMeshMatchesTheBlockAndBends) {
  Block3Spec b;
  b.x1 = 0.4, b.y1 = 0.2, b.z1 = 0.1;
  b.nx = 8, b.ny = 4, b.nz = 2;
  const Mesh box3 = block_mesh_3d(b);
  HexGridSpec h;
  h.ni = 8, h.nj = 4, h.nk = 2;
  h.node = [](int i, int j, int k) { return Vec{0.05 * i, 0.05 * j, 0.05 * k}; };
  const Mesh hex = structured_hex_mesh(h);
  ASSERT_EQ(hex.cells(), box3.cells());
  EXPECT_EQ(hex.faces(), box3.faces());
  EXPECT_EQ(hex.n_internal, box3.n_internal);
  for (const char* p : {"bottom", "top", "left", "right", "back", "front"}) EXPECT_EQ(hex.patch(p).size, box3.patch(p).size) << p;
  for (int c = 0; c < hex.cells(); ++c) {
    EXPECT_NEAR(hex.volume[std::size_t(c)], box3.volume[std::size_t(c)], 1e-15);
    EXPECT_NEAR(norm(hex.centre[std::size_t(c)] - box3.centre[std::size_t(c)]), 0, 1e-12);
  }
  // A quarter annulus (radii 1 to 1.2 m, 40 straight segments) 0.1 m deep: closed, its volume the
  // polygon's, 40 (1.2^2 - 1) sin(pi / 80) / 2 x 0.1.
  h.ni = 40, h.nj = 4, h.nk = 3;
  h.node = [](int i, int j, int k) {
    const double a = 1.5707963267948966 * i / 40, r = 1 + 0.05 * j;
    return Vec{r * std::cos(a), r * std::sin(a), 0.1 * k / 3.0};
  };
  const Mesh bent = structured_hex_mesh(h);  // finish() checks that every cell is closed
  double v = 0;
  for (double x : bent.volume) v += x;
  EXPECT_NEAR(v, 40 * 0.44 * std::sin(3.14159265358979 / 80) / 2 * 0.1, 1e-12);
  h.node = [](int i, int j, int k) { return Vec{0.1 * i, 0.0 * j, 0.1 * k}; };  // flat cells
  EXPECT_THROW(structured_hex_mesh(h), std::invalid_argument);
}

// 3D meshes: hexahedral blocks with obstacles blocked out cell by cell.
TEST(VofMesh, Block3dAddressingAndACylinderObstacle) {
  Block3Spec b;
  b.x1 = 0.1;
  b.y1 = 0.05;
  b.z0 = -0.05;
  b.z1 = 0.05;
  b.nx = 10;
  b.ny = 5;
  b.nz = 10;
  Mesh plain = block_mesh_3d(b);
  EXPECT_EQ(plain.cells(), 500);
  EXPECT_EQ(plain.n_internal, 9 * 5 * 10 + 10 * 4 * 10 + 10 * 5 * 9);
  for (const char* p : {"bottom", "top", "left", "right", "back", "front"}) EXPECT_GE(plain.patch_index(p), 0) << p;
  EXPECT_EQ(plain.patch("front").size, 50);
  b.blocked = [](const Vec& c) { return std::hypot(c.x - 0.05, c.z) < 0.02 && c.y < 0.03; };  // a cylinder on the floor
  Mesh m = block_mesh_3d(b);
  EXPECT_LT(m.cells(), 500);
  EXPECT_GT(m.patch("obstacle").size, 0);
  double vol = 0;
  for (double v : m.volume) vol += v;
  EXPECT_NEAR(vol, 0.1 * 0.05 * 0.1 - 3 * 12 * 1e-6, 1e-9);  // 12 columns of 3 cells (1 cm) blocked
}

// A structured hex mesh with cells left out: the others keep their order, the faces towards the
// left-out cells form one patch, and patches of equal names merge.
TEST(VofMesh, StructuredHexMeshLeavesOutBlockedCellsAndMergesPatches) {
  HexGridSpec s;
  s.ni = 4;
  s.nj = 2;
  s.nk = 3;
  s.node = [](int i, int j, int k) { return Vec{0.1 * i, 0.05 * j + 0.01 * i, 0.1 * k}; };
  s.blocked = [](int i, int, int k) { return i == 3 && k == 2; };  // one column of two cells
  s.patch_names = {"sides", "sides", "ground", "top", "sides", "sides", "cut"};
  const Mesh m = structured_hex_mesh(s);
  EXPECT_EQ(m.cells(), 4 * 2 * 3 - 2);
  EXPECT_EQ(m.patches.size(), 4u);
  EXPECT_EQ(m.patch("ground").size, 4 * 3 - 1);
  EXPECT_EQ(m.patch("top").size, 4 * 3 - 1);
  // Around the domain 2 (4 + 3) columns of faces, less the 2 the left-out column had, twice (2 layers).
  EXPECT_EQ(m.patch("sides").size, (2 * (4 + 3) - 2) * 2);
  EXPECT_EQ(m.patch("cut").size, 2 * 2);  // its two neighbours, both layers
  double v = 0;
  for (double c : m.volume) v += c;
  EXPECT_NEAR(v, 0.4 * 0.1 * 0.3 - 0.1 * 0.1 * 0.1, 1e-15);
  // Nothing blocked: the numbering of an unblocked mesh.
  s.blocked = nullptr;
  const Mesh full = structured_hex_mesh(s);
  EXPECT_EQ(full.cells(), 24);
  EXPECT_NEAR(full.centre[(2 * 2 + 1) * 4 + 3].x, 0.35, 1e-15);  // cell (3, 1, 2)
}
