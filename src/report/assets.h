#pragma once
// Files embedded in the binary at build time (assets.cpp.in): the explorer page's HTML, JS and CSS
// (web/), the vendored Plotly bundle (node_modules, installed by `make deps`), the figure
// script and its reader of packed arrays.

#include <string_view>

namespace lamina::assets {

std::string_view explorer_html();
std::string_view explorer_js();
/// web/colour.js: the explorer's colour view and its colour science (sRGB, CIELAB, CIEDE2000).
std::string_view colour_js();
std::string_view explorer_css();
/// The live spheres (web/spheres.js) and the GLSL they load: lamina-1's, lamina-coat's and its
/// table (docs/explorer.md, "Live spheres").
std::string_view spheres_js();
std::string_view lamina1_glsl();
std::string_view lamina_coat_glsl();
std::string_view lamina_coat_tables_csv();
/// web/model-colors.json: the one table of model colours, for the page and the figures.
std::string_view model_colors_json();
/// Empty when node_modules/plotly.js-dist-min was absent when the build was configured.
std::string_view plotly_js();
std::string_view figures_py();
/// src/python/lamina/arrays.py: the Python reader of packed arrays, which the figure script runs.
std::string_view arrays_py();

}  // namespace lamina::assets
