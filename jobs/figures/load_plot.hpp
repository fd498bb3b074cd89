#pragma once
// The structures' loads over time as PNG and PDF (Cairo, Pango): per structure the horizontal force
// of the flow on it [kN] and the highest pressure on any of its faces [kPa], in two panels over the
// same time axis, with each structure's peak marked.
#include <string>
#include <vector>

namespace runout::figures {

struct LoadPlot {
  std::string title;  ///< UTF-8
  std::string note;   ///< under the title
  struct Structure {
    std::string name;
    std::vector<double> t, force_kn, pressure_kpa;
  };
  std::vector<Structure> structures;
};

/// Draw into `png_path` and `pdf_path` (either may be empty). Throws std::runtime_error when no
/// structure has two samples, or naming a file that cannot be written.
void draw_load_plot(const std::string& png_path, const std::string& pdf_path, const LoadPlot& p);

}  // namespace runout::figures
