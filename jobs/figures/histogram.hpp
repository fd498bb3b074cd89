#pragma once
// A histogram as PNG and PDF (Cairo, Pango): the distribution of one figure over an ensemble's
// members (the runout along the path), with its percentiles marked.
#include <string>
#include <vector>

namespace runout::figures {

struct Histogram {
  std::string title;   ///< UTF-8, wrapped
  std::string note;    ///< under the title
  std::string x_label; ///< e.g. "runout along the path [m]"
  std::vector<double> values;  ///< one per member (non-finite ones are left out)
  std::vector<std::pair<std::string, double>> marks;  ///< named vertical lines (e.g. "p50", 2310)
};

/// The bins: about sqrt(n) (5 to 30) of one round width. Returns the bins' lower edges and counts.
struct Bins {
  double start = 0, width = 1;
  std::vector<int> counts;
};
Bins histogram_bins(const std::vector<double>& values);

/// Draw into `png_path` and `pdf_path` (either may be empty). Throws std::runtime_error.
void draw_histogram(const std::string& png_path, const std::string& pdf_path, const Histogram& h);

}  // namespace runout::figures
