#pragma once
// The report of a run as one multi-page PDF for a hazard report as it is (Cairo, Pango): A4 or A3
// landscape; the summary pages (the parameters in words with units, the mass balance, the results,
// the points of interest's and the zones' tables, the DEM's attribution, version, dates, the
// disclaimer), one page per map at a stated 1:N scale with its cells as a 300 dpi raster (map_page),
// and the path profile. The text is text (searchable, copyable), the lines are vectors.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/profile_plot.hpp"

namespace runout::figures {

struct ReportSection {
  std::string title;
  std::vector<std::string> lines;
};
struct ReportTable {
  std::string title;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Report {
  std::string paper = "a4";  ///< a4 or a3 (landscape)
  std::string title, subtitle;
  std::vector<ReportSection> sections;
  std::vector<ReportTable> tables;
  std::string footer;      ///< on every page (software, dates, the DEM's attribution)
  std::string disclaimer;  ///< on the first page
  terrain::Grid grid;
  std::array<double, 4> extent{};  ///< what the maps show (grid's CRS); all 0: the grid
  std::vector<HazardMap> maps;
  std::optional<ProfilePlot> profile;
  double dpi = 300;
};

struct ReportLayout {
  int pages = 0;
  double page_w = 0, page_h = 0;  ///< [pt]
  std::vector<MapPageLayout> maps;
  int unknown_glyphs = 0;
};

/// Write the report to `pdf_path`. Throws std::runtime_error (a paper other than a4 or a3, a file
/// that cannot be written) or terrain::TerrainError.
ReportLayout write_report(const std::string& pdf_path, const Report& r);

}  // namespace runout::figures
