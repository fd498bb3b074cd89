#pragma once
// The aggregate of a zoning (scenario `zoning`, docs/user/zoning.md): once the scenario of every
// return period has run, their maximum depth and pressure are read and turned into
//   - zones.tif (classes yellow, blue, red; COG with category names and colours), zones.qml, and the
//     zones as polygons (zones.geojson in WGS84, zones.gpkg), with map_zones.png/.pdf;
//   - beside them each scenario's depth and pressure rasters and pressure map, named by its return
//     period (max_depth_<T>y.tif, max_pressure_<T>y.tif, map_max_pressure_<T>y.png/.pdf);
//   - run.json: the record (runout.v1.EnsembleRecord, kind "zoning", with its ZoningResult).
#include <functional>
#include <string>
#include <vector>

#include "jobs/drivers/ensemble_aggregate.hpp"

namespace runout::jobs {

/// The zones of a zoning's members (one per return period, ascending) into `out_dir` (existing,
/// empty); as aggregate_ensemble.
v1::EnsembleRecord aggregate_zoning(const ResolvedScenario& zoning, const std::vector<MemberResults>& members,
                                    const std::string& out_dir, const std::function<bool(int, int)>& progress = {});

}  // namespace runout::jobs
