#pragma once
// The simulated runout against an observed outline: hits, false alarms and misses per cell, their
// areas, the critical success index and the ROC point (as AvaFrame's and the ISeeSnow benchmark's
// comparisons report them).
#include <cstdint>
#include <vector>

#include "jobs/figures/palette.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs::products {

struct OutlineScores {
  std::vector<std::uint8_t> cls;  ///< per cell: 0 neither, 1 hit (TP), 2 false alarm (FP), 3 miss (FN)
  double observed_m2 = 0, simulated_m2 = 0;
  double tp_m2 = 0, fp_m2 = 0, fn_m2 = 0, tn_m2 = 0;  ///< over the cells of the domain
  double csi = 0;  ///< TP / (TP + FP + FN); 0 when all three are 0
  double tpr = 0;  ///< TP / (TP + FN)
  double fpr = 0;  ///< FP / (FP + TN)
};

/// Score `simulated` (per cell) against `observed` (per cell) on the grid's domain.
OutlineScores outline_scores(const terrain::Grid& g, const std::vector<std::uint8_t>& simulated, const std::vector<std::uint8_t>& observed);

/// The classes' palette for the map (class k + 1 from k + 1).
figures::Palette score_palette();

}  // namespace runout::jobs::products
