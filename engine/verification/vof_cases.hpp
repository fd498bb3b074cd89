#pragma once
// Verification cases V1-V7 of the VOF engine (engine/vof/, docs/validation/verification.md): Newtonian flows
// with exact solutions (plane Couette, plane Poiseuille, Couette's start-up), a two-layer column
// at rest (hydrostatic pressure, no spurious currents) and the Bagnold flow of the mu(I) rheology, with and without its regularisation and between side walls. Same rows and registry as A1-A7 (cases.cpp).
#include <vector>

#include "engine/verification/cases.hpp"

namespace runout::engine::verification {

std::vector<Row> case_v1(const Options& o);  ///< plane Couette flow, steady
std::vector<Row> case_v2(const Options& o);  ///< plane Poiseuille flow down an inclined channel
std::vector<Row> case_v3(const Options& o);  ///< still two-layer column in a closed box
std::vector<Row> case_v4(const Options& o);  ///< start-up of plane Couette flow (transient)
std::vector<Row> case_v5(const Options& o);  ///< Bagnold flow of the mu(I) rheology down an inclined plane
std::vector<Row> case_v6(const Options& o);  ///< the same at low I: regularised against unregularised
std::vector<Row> case_v7(const Options& o);  ///< the same between side walls with Coulomb friction

}  // namespace runout::engine::verification
