#pragma once
// The longitudinal profiles of a path analysis as PNG and PDF (Cairo, Pango): the ground along the
// path with the runout and beta points and the alpha line, and below it the largest depth, speed and
// pressure of each cross-section.
#include <string>
#include <utility>
#include <vector>

// Cairo's context, declared as cairo.h does (the header itself stays inside jobs/figures).
typedef struct _cairo cairo_t;

namespace runout::figures {

struct ProfilePlot {
  std::string title;  ///< UTF-8
  std::vector<double> s, z;  ///< stations [m] and the ground [m]
  struct Series {
    std::string label;  ///< e.g. "max depth [m]"
    std::vector<double> v;
  };
  std::vector<Series> series;
  double runout_s = -1, beta_s = -1;  ///< [m]; < 0: none
  double alpha_deg = 0;
  std::string note;  ///< under the title, e.g. the criterion
};

/// The plot's size (width, height) in page units. Throws std::runtime_error with fewer than two stations.
std::pair<double, double> profile_plot_size(const ProfilePlot& p);

/// Draw the plot at (0, 0) of `cr` at the size profile_plot_size gives.
void draw_profile(cairo_t* cr, const ProfilePlot& p);

/// Draw into `png_path` and `pdf_path` (either may be empty). Throws std::runtime_error.
void draw_profile_plot(const std::string& png_path, const std::string& pdf_path, const ProfilePlot& p);

}  // namespace runout::figures
