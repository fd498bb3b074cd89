#include "engine/vof/mpi/partition.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include <scotch.h>

#include "engine/vof/error.hpp"

namespace runout::engine::vof {

namespace {

// The graph PT-Scotch splits: one vertex per column and per cell outside every column, an edge
// between two vertices whose cells share an internal face, each vertex weighted by its cells.
struct CellGraph {
  std::vector<int> vertex_of;  // per cell
  std::vector<SCOTCH_Num> start{0}, adj, weight;
  int vertices() const { return int(weight.size()); }
};

CellGraph cell_graph(const Mesh& m, const MeshColumns& cols) {
  CellGraph g;
  const int nc = m.cells();
  g.vertex_of.assign(std::size_t(nc), -1);
  for (int k = 0; k < cols.columns(); ++k)
    for (int i = cols.start[std::size_t(k)]; i < cols.start[std::size_t(k) + 1]; ++i) g.vertex_of[std::size_t(cols.cells[std::size_t(i)])] = k;
  int nv = cols.columns();
  for (int c = 0; c < nc; ++c)
    if (g.vertex_of[std::size_t(c)] < 0) g.vertex_of[std::size_t(c)] = nv++;
  g.weight.assign(std::size_t(nv), 0);
  for (int c = 0; c < nc; ++c) ++g.weight[std::size_t(g.vertex_of[std::size_t(c)])];
  std::vector<std::vector<SCOTCH_Num>> nb(static_cast<std::size_t>(nv));
  for (int f = 0; f < m.n_internal; ++f) {
    const int a = g.vertex_of[std::size_t(m.owner[f])], b = g.vertex_of[std::size_t(m.neighbour[f])];
    if (a == b) continue;
    nb[std::size_t(a)].push_back(b);
    nb[std::size_t(b)].push_back(a);
  }
  for (auto& l : nb) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    g.adj.insert(g.adj.end(), l.begin(), l.end());
    g.start.push_back(SCOTCH_Num(g.adj.size()));
  }
  return g;
}

// Scotch's split of the graph into `parts`, in a context of one thread with its deterministic and
// fixed-seed options (Debian's Scotch otherwise splits over threads, and the same graph came back
// split differently from call to call): the same graph gives the same split in every process.
std::vector<int> split_graph(const CellGraph& g, int parts) {
  std::vector<SCOTCH_Num> vert = g.start, edge = g.adj, load = g.weight;
  SCOTCH_Context ctx;
  SCOTCH_Graph graph, bound;
  SCOTCH_Strat strat;
  if (SCOTCH_contextInit(&ctx) != 0) throw VofError("ranks: Scotch could not start");
  SCOTCH_contextOptionSetNum(&ctx, SCOTCH_OPTIONNUMDETERMINISTIC, 1);
  SCOTCH_contextOptionSetNum(&ctx, SCOTCH_OPTIONNUMRANDOMFIXEDSEED, 1);
  SCOTCH_contextRandomSeed(&ctx, 1);
  SCOTCH_graphInit(&graph);
  SCOTCH_graphInit(&bound);
  SCOTCH_stratInit(&strat);
  std::vector<SCOTCH_Num> part(std::size_t(g.vertices()), 0);
  int rc = SCOTCH_contextThreadSpawn(&ctx, 1, nullptr);
  if (rc == 0)
    rc = SCOTCH_graphBuild(&graph, 0, SCOTCH_Num(g.vertices()), vert.data(), nullptr, load.data(), nullptr, SCOTCH_Num(edge.size()), edge.data(),
                           nullptr);
  if (rc == 0) rc = SCOTCH_contextBindGraph(&ctx, &graph, &bound);
  if (rc == 0) rc = SCOTCH_graphPart(&bound, SCOTCH_Num(parts), &strat, part.data());
  SCOTCH_stratExit(&strat);
  SCOTCH_graphExit(&bound);
  SCOTCH_graphExit(&graph);
  SCOTCH_contextExit(&ctx);
  if (rc != 0) throw VofError("ranks: Scotch could not split the mesh's graph into " + std::to_string(parts) + " parts");
  return {part.begin(), part.end()};
}

// The horizontal direction (across gravity) in which the cells spread least, and their spread
// along it: across the flow on a chute or along an avalanche's path. Zero where the cells do not
// spread across gravity in two directions (a plane mesh).
Vec across_direction(const Mesh& m, const Vec& gravity, double& spread) {
  spread = 0;
  const double gn = norm(gravity);
  if (!(gn > 0)) return {};
  const Vec up = (-1.0 / gn) * gravity;
  // Two axes of the horizontal plane, then the 2 x 2 covariance of the centres in it.
  const Vec pick = std::abs(up.x) < 0.9 ? Vec{1, 0, 0} : Vec{0, 0, 1};
  Vec e1 = pick - dot(pick, up) * up;
  e1 = (1.0 / norm(e1)) * e1;
  const Vec e2{up.y * e1.z - up.z * e1.y, up.z * e1.x - up.x * e1.z, up.x * e1.y - up.y * e1.x};
  double s1 = 0, s2 = 0, s11 = 0, s22 = 0, s12 = 0;
  const double n = m.cells();
  for (int c = 0; c < m.cells(); ++c) {
    const double a = dot(m.centre[c], e1), b = dot(m.centre[c], e2);
    s1 += a, s2 += b, s11 += a * a, s22 += b * b, s12 += a * b;
  }
  const double c11 = s11 / n - (s1 / n) * (s1 / n), c22 = s22 / n - (s2 / n) * (s2 / n), c12 = s12 / n - (s1 / n) * (s2 / n);
  // The eigenvector of the smaller eigenvalue.
  const double tr = c11 + c22, det = c11 * c22 - c12 * c12, lo = 0.5 * tr - std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
  Vec d = std::abs(c12) > 1e-300 ? (c12 * e1 + (lo - c11) * e2) : (c11 <= c22 ? e1 : e2);
  d = (1.0 / norm(d)) * d;
  double lo_x = 1e300, hi_x = -1e300;
  for (int c = 0; c < m.cells(); ++c) {
    lo_x = std::min(lo_x, dot(m.centre[c], d));
    hi_x = std::max(hi_x, dot(m.centre[c], d));
  }
  spread = hi_x - lo_x;
  return d;
}

// Strips along the flow: the graph's vertices (columns, loose cells) in order of their mean
// position across it, cut into `parts` runs of (nearly) equal cells.
std::vector<int> strips(const Mesh& m, const CellGraph& g, const Vec& across, int parts) {
  const int nv = g.vertices();
  std::vector<double> pos(std::size_t(nv), 0.0);
  for (int c = 0; c < m.cells(); ++c) pos[std::size_t(g.vertex_of[std::size_t(c)])] += dot(m.centre[c], across);
  std::vector<int> order(static_cast<std::size_t>(nv));
  for (int v = 0; v < nv; ++v) {
    pos[std::size_t(v)] /= double(g.weight[std::size_t(v)]);
    order[std::size_t(v)] = v;
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return pos[std::size_t(a)] < pos[std::size_t(b)]; });
  std::vector<int> vpart(static_cast<std::size_t>(nv));
  long long before = 0;
  const double total = m.cells();
  for (int v : order) {
    const auto w = g.weight[std::size_t(v)];
    vpart[std::size_t(v)] = std::min(parts - 1, int((double(before) + 0.5 * double(w)) * parts / total));
    before += w;
  }
  return vpart;
}

}  // namespace

Partition partition_figures(const Mesh& m, std::vector<int> part, int parts) {
  Partition p;
  p.part = std::move(part);
  p.parts = parts;
  std::vector<long long> n(std::size_t(parts), 0);
  for (int r : p.part) ++n[std::size_t(r)];
  for (int f = 0; f < m.n_internal; ++f)
    if (p.part[std::size_t(m.owner[f])] != p.part[std::size_t(m.neighbour[f])]) ++p.cut_faces;
  const double mean = double(m.cells()) / parts;
  p.imbalance = mean > 0 ? double(*std::max_element(n.begin(), n.end())) / mean : 1;
  return p;
}

Partition partition_cells(const Mesh& m, const MeshColumns& columns, int parts, const Vec& gravity) {
  if (parts < 1) throw VofError("ranks: must be at least 1 (was " + std::to_string(parts) + ")");
  if (parts == 1) return partition_figures(m, std::vector<int>(std::size_t(m.cells()), 0), 1);
  const CellGraph g = cell_graph(m, columns);
  if (g.vertices() < parts)
    throw VofError("ranks: " + std::to_string(parts) + " ranks for a mesh of " + std::to_string(g.vertices()) +
                   (columns.columns() > 0 ? " columns" : " cells") + " (at most one rank per column)");
  // Strips along the flow where the cells spread across it over at least two cells per strip; else
  // Scotch's split of the graph.
  double spread = 0;
  const Vec across = across_direction(m, gravity, spread);
  const bool by_strips = spread > 2.0 * parts * m.mean_cell_size();
  const auto vpart = by_strips ? strips(m, g, across, parts) : split_graph(g, parts);
  // The parts numbered in the order of their first cells (Scotch's own numbers vary from call to call).
  std::vector<int> part(std::size_t(m.cells())), label(std::size_t(parts), -1);
  int next = 0;
  for (int c = 0; c < m.cells(); ++c) {
    int& l = label[std::size_t(vpart[std::size_t(g.vertex_of[std::size_t(c)])])];
    if (l < 0) l = next++;
    part[std::size_t(c)] = l;
  }
  std::vector<char> used(std::size_t(parts), 0);
  for (int r : part) used[std::size_t(r)] = 1;
  if (std::find(used.begin(), used.end(), 0) != used.end())
    throw VofError("ranks: the partitioner left a rank of " + std::to_string(parts) + " without cells");
  Partition out = partition_figures(m, std::move(part), parts);
  out.strips = by_strips;
  out.across = across;
  return out;
}

}  // namespace runout::engine::vof
