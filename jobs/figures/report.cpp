#include "jobs/figures/report.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "jobs/figures/pen.hpp"

namespace runout::figures {
namespace {

const Rgb kText{0.1, 0.1, 0.1}, kRule{0.6, 0.6, 0.6};
constexpr double kMargin = 36;  // half an inch

// Pages with a footer; text flows down and onto a new page when the page is full.
class Pages {
 public:
  Pages(cairo_t* cr, double w, double h, std::string footer, ReportLayout& lay) : cr_(cr), w_(w), h_(h), footer_(std::move(footer)), lay_(lay) {}
  double y = kMargin;
  double width() const { return w_ - 2 * kMargin; }
  double bottom() const { return h_ - kMargin - 24; }
  // Room for `height` more on this page, else a new one.
  void need(double height) {
    if (y + height > bottom()) next();
  }
  void next() {
    finish_page();
    cairo_show_page(cr_);
    y = kMargin;
  }
  void finish_page() {
    ++lay_.pages;
    text(kMargin, h_ - kMargin - 10, footer_ + "  ·  page " + std::to_string(lay_.pages), {7, false, kRule, width()});
  }
  double text(double x, double yy, const std::string& s, const TextStyle& st) {
    const auto b = draw_text(cr_, x, yy, s, st);
    lay_.unknown_glyphs += b.unknown_glyphs;
    return b.h;
  }
  cairo_t* cr() const { return cr_; }

 private:
  cairo_t* cr_;
  double w_, h_;
  std::string footer_;
  ReportLayout& lay_;
};

void section(Pages& p, const ReportSection& s) {
  p.need(40);
  p.y += p.text(kMargin, p.y, s.title, {12, true, kText}) + 4;
  for (const auto& line : s.lines) {
    const double h = draw_text(nullptr, 0, 0, line, {9, false, kText, p.width()}).h;
    p.need(h + 2);
    p.y += p.text(kMargin, p.y, line, {9, false, kText, p.width()}) + 2;
  }
  p.y += 10;
}

// A table: the columns as wide as their widest cell (the last takes the rest), a rule under the head.
void table(Pages& p, const ReportTable& t) {
  if (t.rows.empty()) return;
  const TextStyle cell{8.5, false, kText}, head{8.5, true, kText};
  std::vector<double> w(t.header.size(), 0);
  for (std::size_t c = 0; c < t.header.size(); ++c) {
    w[c] = draw_text(nullptr, 0, 0, t.header[c], head).w;
    for (const auto& r : t.rows)
      if (c < r.size()) w[c] = std::max(w[c], draw_text(nullptr, 0, 0, r[c], cell).w);
  }
  p.need(60);
  p.y += p.text(kMargin, p.y, t.title, {12, true, kText}) + 4;
  // The columns share the page's width: the last one gets what is left (at least a fifth) and wraps.
  double others = 0;
  for (std::size_t c = 0; c + 1 < w.size(); ++c) others += w[c] + 14;
  if (!w.empty()) w.back() = std::min(w.back(), std::max(p.width() - others, p.width() / 5));
  auto row = [&](const std::vector<std::string>& cells, const TextStyle& st) {
    double x = kMargin, h = 12;
    for (std::size_t c = 0; c < cells.size() && c < w.size(); ++c)
      h = std::max(h, draw_text(nullptr, 0, 0, cells[c], {st.size, st.bold, st.colour, c + 1 == w.size() ? w[c] : -1}).h);
    p.need(h + 2);
    for (std::size_t c = 0; c < cells.size() && c < w.size(); ++c) {
      const bool number = &st == &cell && c > 0 && c + 1 < w.size();  // numbers right-aligned
      p.text(number ? x + w[c] : x, p.y, cells[c], {st.size, st.bold, st.colour, c + 1 == w.size() ? w[c] : -1, 0, number ? 2 : 0});
      x += w[c] + 14;
    }
    p.y += h + 2;
  };
  row(t.header, head);
  cairo_move_to(p.cr(), kMargin, p.y - 1);
  cairo_line_to(p.cr(), p.width() + kMargin, p.y - 1);
  stroke(p.cr(), kRule, 0.5);
  for (const auto& r : t.rows) row(r, cell);
  p.y += 12;
}

}  // namespace

ReportLayout write_report(const std::string& pdf_path, const Report& r) {
  ReportLayout lay;
  constexpr double kPt = 72 / 25.4;  // points per millimetre
  if (r.paper == "a4") lay.page_w = 297 * kPt, lay.page_h = 210 * kPt;
  else if (r.paper == "a3") lay.page_w = 420 * kPt, lay.page_h = 297 * kPt;
  else throw std::runtime_error("report: paper '" + r.paper + "' (valid: a4, a3)");
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(cairo_pdf_surface_create(pdf_path.c_str(), lay.page_w, lay.page_h),
                                                                          cairo_surface_destroy);
  cairo_pdf_surface_set_metadata(surf.get(), CAIRO_PDF_METADATA_TITLE, r.title.c_str());
  cairo_pdf_surface_set_metadata(surf.get(), CAIRO_PDF_METADATA_CREATOR, "runout");
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surf.get()), cairo_destroy);
  Pages p(cr.get(), lay.page_w, lay.page_h, r.footer, lay);
  // The summary.
  p.y += p.text(kMargin, p.y, r.title, {18, true, kText, p.width()}) + 4;
  p.y += p.text(kMargin, p.y, r.subtitle, {10, false, kText, p.width()}) + 14;
  for (const auto& s : r.sections) section(p, s);
  for (const auto& t : r.tables) table(p, t);
  if (!r.disclaimer.empty()) {
    p.need(draw_text(nullptr, 0, 0, r.disclaimer, {8, false, kText, p.width()}).h + 8);
    p.y += p.text(kMargin, p.y, r.disclaimer, {8, false, kText, p.width()}) + 8;
  }
  // One page per map: the title, the map at its scale, the legend to its right.
  const double panel_w = 0.75 * 290 + 10;
  for (const auto& m : r.maps) {
    p.next();
    p.y += p.text(kMargin, p.y, m.title, {13, true, kText, p.width()}) + 8;
    MapPageSpec spec;
    spec.x = kMargin + 16;
    spec.y = p.y;
    spec.w = lay.page_w - 2 * kMargin - 16 - panel_w;
    spec.h = p.bottom() - p.y - 40;
    spec.panel_x = spec.x + spec.w + 12;
    spec.panel_y = p.y;
    spec.dpi = r.dpi;
    spec.extent = r.extent;
    lay.maps.push_back(draw_map_page(cr.get(), r.grid, m, spec));
    lay.unknown_glyphs += lay.maps.back().unknown_glyphs;
  }
  if (r.profile) {  // the profile scaled to the page
    p.next();
    const auto [w, h] = profile_plot_size(*r.profile);
    const double k = std::min((lay.page_w - 2 * kMargin) / w, (p.bottom() - kMargin) / h);
    cairo_save(cr.get());
    cairo_translate(cr.get(), kMargin, kMargin);
    cairo_scale(cr.get(), k, k);
    draw_profile(cr.get(), *r.profile);
    cairo_restore(cr.get());
  }
  p.finish_page();
  cairo_show_page(cr.get());
  cr.reset();
  cairo_surface_finish(surf.get());
  if (cairo_surface_status(surf.get()) != CAIRO_STATUS_SUCCESS) throw std::runtime_error("writing '" + pdf_path + "' failed");
  return lay;
}

}  // namespace runout::figures
