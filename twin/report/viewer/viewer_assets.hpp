#pragma once
// What the report's page runs, built into the program (embed_text.cmake): three.js, its
// glTF loader and orbit controls as Debian's libjs-three ships them, and the report's own
// script and style (report.js, report.css beside this file).

#include <string_view>

namespace twin::viewer {

std::string_view three_js();
std::string_view gltf_loader_js();
std::string_view orbit_controls_js();
std::string_view report_js();
std::string_view report_css();

}  // namespace twin::viewer
