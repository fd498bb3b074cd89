#include "jobs/products/scores.hpp"

namespace runout::jobs::products {

OutlineScores outline_scores(const terrain::Grid& g, const std::vector<std::uint8_t>& sim, const std::vector<std::uint8_t>& obs) {
  OutlineScores s;
  s.cls.assign(g.cells(), 0);
  const double a = g.dx * g.dx;
  for (std::size_t k = 0; k < g.cells(); ++k) {
    if (!g.outside.empty() && g.outside[k]) continue;
    const bool p = sim[k] != 0, o = obs[k] != 0;
    s.cls[k] = p && o ? 1 : p ? 2 : o ? 3 : 0;
    (p && o ? s.tp_m2 : p ? s.fp_m2 : o ? s.fn_m2 : s.tn_m2) += a;
  }
  s.observed_m2 = s.tp_m2 + s.fn_m2;
  s.simulated_m2 = s.tp_m2 + s.fp_m2;
  const double all = s.tp_m2 + s.fp_m2 + s.fn_m2;
  s.csi = all > 0 ? s.tp_m2 / all : 0;
  s.tpr = s.observed_m2 > 0 ? s.tp_m2 / s.observed_m2 : 0;
  s.fpr = s.fp_m2 + s.tn_m2 > 0 ? s.fp_m2 / (s.fp_m2 + s.tn_m2) : 0;
  return s;
}

figures::Palette score_palette() {
  return {"simulated against observed", "",
          {{1, {{26, 152, 80}}, "hit: simulated and observed"},
           {2, {{253, 174, 97}}, "false alarm: simulated only"},
           {3, {{118, 42, 131}}, "miss: observed only"}}};
}

}  // namespace runout::jobs::products
