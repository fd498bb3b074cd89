#include "engine/verification/cases.hpp"

#include <stdexcept>

#include "engine/verification/case_support.hpp"
#include "engine/verification/vof_cases.hpp"

namespace runout::engine::verification {
namespace {

using namespace detail;

struct CaseEntry {
  const char* id;
  const char* text;
  std::vector<Row> (*run)(const Options&);
};
const CaseEntry kCases[] = {
    {"A1", "dam break on an inclined plane with Coulomb friction (Mangeney et al. 2000), 1D and 2D", case_a1},
    {"A2", "parabolic cap on an inclined plane (Savage & Hutter 1989), 1D", case_a2},
    {"A3", "elliptic cap on an inclined plane (Hutter et al. 1993), 2D", case_a3},
    {"A4", "material at rest stays at rest: pile on a flat plane, layer on a gentle slope, 2D", case_a4},
    {"A5", "steady flow down a uniform chute (Pudasaini 2011), 1D with inflow", case_a5},
    {"A6", "rotation invariance: release on slope-to-run-out terrain rotated by 0, 30, 90 deg, 2D", case_a6},
    {"A7", "energy line: alpha angle equals delta for pure Coulomb friction, 2D and curved 1D", case_a7},
    {"STRESS", "randomised terrain, friction, depths, resolutions and CFL: no NaN, no negative depth, no mass drift",
     case_stress},
    {"V1", "VOF engine: plane Couette flow of a Newtonian fluid, steady linear profile", case_v1},
    {"V2", "VOF engine: plane Poiseuille flow of a Newtonian fluid down an inclined channel, parabolic profile", case_v2},
    {"V3", "VOF engine: granular layer under air at rest in a closed box, hydrostatic pressure, no spurious currents", case_v3},
    {"V4", "VOF engine: start-up of plane Couette flow from rest (series solution)", case_v4},
    {"V5", "VOF engine: steady Bagnold flow of the mu(I) rheology down an inclined plane, under air", case_v5},
    {"V6", "VOF engine: Bagnold flow at low inertial number, mu(I) regularised (converges) and not (does not)", case_v6},
    {"V7", "VOF engine: mu(I) flow down an inclined plane between side walls with Coulomb friction (Jop et al. 2005)", case_v7},
};

}  // namespace

std::vector<std::string> case_ids() {
  std::vector<std::string> v;
  for (const auto& c : kCases) v.emplace_back(c.id);
  return v;
}

std::string describe(const std::string& id) {
  for (const auto& c : kCases)
    if (id == c.id) return c.text;
  return {};
}

std::vector<Row> run_case(const std::string& id, const Options& opt) {
  for (const auto& c : kCases)
    if (id == c.id) return c.run(opt);
  std::string valid;
  for (const auto& c : kCases) valid += (valid.empty() ? "" : ", ") + std::string(c.id);
  throw std::invalid_argument("unknown verification case '" + id + "' (valid: " + valid + ")");
}

}  // namespace runout::engine::verification
