#include "jobs/figures/qml.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace runout::figures {
namespace {

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

void write(const std::string& path, const std::string& renderer) {
  write_qml(path, "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n<qgis version=\"3.28\" styleCategories=\"Symbology\">\n  <pipe>\n" +
                      renderer + "  </pipe>\n  <blendMode>0</blendMode>\n</qgis>\n");
}

std::string rgba(const Rgb8& c, int alpha) {
  return std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) + "," + std::to_string(alpha);
}

// A fill symbol: its fill (alpha 0: none) and outline, widths in millimetres.
std::string fill_symbol(const std::string& name, const Rgb8& fill, int fill_alpha, const Rgb8& line, double width_mm) {
  std::ostringstream s;
  auto opt = [&](const char* k, const std::string& v) { s << "            <Option name=\"" << k << "\" value=\"" << v << "\" type=\"QString\"/>\n"; };
  s << "      <symbol type=\"fill\" name=\"" << name << "\" alpha=\"1\" clip_to_extent=\"1\" force_rhr=\"0\">\n"
    << "        <layer class=\"SimpleFill\" enabled=\"1\" locked=\"0\" pass=\"0\">\n          <Option type=\"Map\">\n";
  opt("color", rgba(fill, fill_alpha));
  opt("style", fill_alpha > 0 ? "solid" : "no");
  opt("outline_color", rgba(line, 255));
  opt("outline_style", "solid");
  opt("outline_width", num(width_mm));
  opt("outline_width_unit", "MM");
  opt("joinstyle", "miter");
  s << "          </Option>\n        </layer>\n      </symbol>\n";
  return s.str();
}

std::string vector_document(const std::string& renderer) {
  return "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n<qgis version=\"3.22\" styleCategories=\"Symbology\">\n" + renderer +
         "  <blendMode>0</blendMode>\n  <featureBlendMode>0</featureBlendMode>\n  <layerGeometryType>2</layerGeometryType>\n</qgis>\n";
}

}  // namespace

void write_qml(const std::string& path, const std::string& qml) {
  std::ofstream f(path);
  f << qml;
  if (!f) throw std::runtime_error("writing '" + path + "' failed");
}

std::string qml_polygon_classes(const Palette& p, const std::vector<std::string>& names) {
  std::ostringstream r;
  r << "  <renderer-v2 type=\"categorizedSymbol\" attr=\"name\" symbollevels=\"0\" enableorderby=\"0\" forceraster=\"0\">\n"
    << "    <categories>\n";
  for (std::size_t k = 0; k < p.classes.size() && k < names.size(); ++k)
    r << "      <category render=\"true\" symbol=\"" << k << "\" value=\"" << xml_escape(names[k]) << "\" label=\""
      << xml_escape(p.classes[k].label) << "\"/>\n";
  r << "    </categories>\n    <symbols>\n";
  for (std::size_t k = 0; k < p.classes.size() && k < names.size(); ++k)
    r << fill_symbol(std::to_string(k), p.classes[k].colour, 115, p.classes[k].colour, 0.5);
  r << "    </symbols>\n  </renderer-v2>\n";
  return vector_document(r.str());
}

std::string qml_outline() {
  const Rgb8 line{{110, 0, 20}};  // the maps' outline colour
  return vector_document("  <renderer-v2 type=\"singleSymbol\" symbollevels=\"0\" enableorderby=\"0\" forceraster=\"0\">\n    <symbols>\n" +
                         fill_symbol("0", line, 0, line, 0.6) + "    </symbols>\n  </renderer-v2>\n");
}

void write_qml_ramp(const std::string& path, const Palette& p) {
  if (p.classes.empty()) throw std::logic_error("write_qml_ramp: an empty palette");
  const double lo = p.classes.front().from, hi = p.classes.back().from;
  std::ostringstream r;
  r << "    <rasterrenderer type=\"singlebandpseudocolor\" band=\"1\" opacity=\"1\" alphaBand=\"-1\" classificationMin=\""
    << num(lo) << "\" classificationMax=\"" << num(hi) << "\">\n"
    << "      <rastershader>\n        <colorrampshader colorRampType=\"DISCRETE\" classificationMode=\"3\" clip=\"0\" minimumValue=\""
    << num(lo) << "\" maximumValue=\"" << num(hi) << "\" labelPrecision=\"3\">\n";
  // QGIS's discrete ramp: an item colours the values up to its value.
  r << "          <item alpha=\"0\" value=\"" << num(lo) << "\" label=\"&lt; " << num(lo) << " " << xml_escape(p.unit)
    << "\" color=\"#ffffff\"/>\n";
  for (std::size_t k = 0; k < p.classes.size(); ++k) {
    const std::string upper = k + 1 < p.classes.size() ? num(p.classes[k + 1].from) : "inf";
    r << "          <item alpha=\"255\" value=\"" << upper << "\" label=\"" << xml_escape(p.classes[k].label + " " + p.unit)
      << "\" color=\"" << hex(p.classes[k].colour) << "\"/>\n";
  }
  r << "        </colorrampshader>\n      </rastershader>\n    </rasterrenderer>\n";
  write(path, r.str());
}

void write_qml_classes(const std::string& path, const Palette& p) {
  std::ostringstream r;
  r << "    <rasterrenderer type=\"paletted\" band=\"1\" opacity=\"1\" alphaBand=\"-1\">\n      <colorPalette>\n";
  for (std::size_t k = 0; k < p.classes.size(); ++k)
    r << "        <paletteEntry value=\"" << k + 1 << "\" alpha=\"255\" color=\"" << hex(p.classes[k].colour) << "\" label=\""
      << xml_escape(p.classes[k].label) << "\"/>\n";
  r << "      </colorPalette>\n    </rasterrenderer>\n";
  write(path, r.str());
}

}  // namespace runout::figures
