#pragma once
// The VOF engine's loops over the OpenMP threads. A loop writes only its own element (a face's value
// per face, a cell's per cell); what a face gives its cells is gathered per cell over the cell's
// faces in ascending order (CellFaces), the order in which a serial loop over the faces would have
// added it. So every result is the same, bit for bit, for any number of threads
// (VofSolver.ResultsDoNotDependOnTheThreadCount).
#include <vector>

namespace runout::engine::vof {

/// Below this many elements a loop stays on one thread (the threads' start costs more).
inline constexpr int kParallelMin = 4096;

/// body(i) for i in [0, n), split into fixed shares over the threads.
template <class Body>
void parallel_for(int n, const Body& body) {
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int i = 0; i < n; ++i) body(i);
}

/// body(x) for every element of a list of cells or faces.
template <class Body>
void parallel_each(const std::vector<int>& list, const Body& body) {
  parallel_for(int(list.size()), [&](int i) { body(list[std::size_t(i)]); });
}

}  // namespace runout::engine::vof
