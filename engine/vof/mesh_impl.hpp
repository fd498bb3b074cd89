#pragma once
// Template part of mesh.hpp.
#include <algorithm>
#include <stdexcept>
#include <type_traits>

namespace runout::engine::vof {

template <class Pick>
void split_patch(Mesh& m, const std::string& from, const std::string& to, Pick pick) {
  const int pi = m.patch_index(from);
  if (pi < 0) throw std::invalid_argument("mesh: no patch '" + from + "'");
  const Patch p = m.patches[pi];
  std::vector<int> keep, moved;
  for (int f = p.start; f < p.start + p.size; ++f) {
    bool take;
    if constexpr (std::is_invocable_r_v<bool, Pick, int>) take = pick(f);  // by the face's number
    else take = pick(m.Cf[f]);                                             // by its centre
    (take ? moved : keep).push_back(f);
  }
  if (moved.empty()) return;
  // New face order: everything before the patch, its kept faces, its moved faces, everything after.
  std::vector<int> order;
  for (int f = 0; f < p.start; ++f) order.push_back(f);
  order.insert(order.end(), keep.begin(), keep.end());
  order.insert(order.end(), moved.begin(), moved.end());
  for (int f = p.start + p.size; f < m.faces(); ++f) order.push_back(f);
  auto permute = [&](auto& v) {
    auto old = v;
    for (std::size_t k = 0; k < order.size(); ++k) v[k] = old[order[k]];
  };
  permute(m.owner);
  permute(m.Sf);
  permute(m.Cf);
  // neighbour holds internal faces only, which do not move.
  m.patches[pi].size = int(keep.size());
  Patch np{to, p.start + int(keep.size()), int(moved.size())};
  m.patches.insert(m.patches.begin() + pi + 1, np);
  if (keep.empty()) m.patches.erase(m.patches.begin() + pi);
  m.finish();
}

}  // namespace runout::engine::vof
