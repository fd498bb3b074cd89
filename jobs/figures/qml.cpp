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
  std::ofstream f(path);
  f << "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
    << "<qgis version=\"3.28\" styleCategories=\"Symbology\">\n  <pipe>\n"
    << renderer << "  </pipe>\n  <blendMode>0</blendMode>\n</qgis>\n";
  if (!f) throw std::runtime_error("writing '" + path + "' failed");
}

}  // namespace

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
