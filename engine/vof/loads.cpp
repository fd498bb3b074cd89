#include "engine/vof/loads.hpp"

#include "engine/vof/error.hpp"

namespace runout::engine::vof {

PatchLoad patch_load(const VofBackend& s, const std::string& patch) {
  const Mesh& m = s.mesh();
  const Patch* p = nullptr;
  for (const auto& q : m.patches)
    if (q.name == patch) p = &q;
  if (!p) throw VofError("loads: the mesh has no patch '" + patch + "'");
  PatchLoad out;
  out.face_pressure.resize(std::size_t(p->size));
  for (int q = 0; q < p->size; ++q) {
    const int f = p->start + q;
    const double pf = s.face_pressure(f);
    out.face_pressure[std::size_t(q)] = pf;
    out.force = out.force + pf * m.Sf[std::size_t(f)];
    out.area += m.magSf[std::size_t(f)];
    if (pf > out.max_pressure) {
      out.max_pressure = pf;
      out.max_face = f;
    }
  }
  return out;
}

}  // namespace runout::engine::vof
