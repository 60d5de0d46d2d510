#pragma once
// The dashboard's page, script and style (deploy/cellctl/dashboard/), built into cellctl by
// twin/report/viewer/embed_text.cmake; three.js is the report's (twin/report/viewer).

#include <string_view>

namespace cellctl::dashboard {

std::string_view page_html();
std::string_view script_js();
std::string_view style_css();

}  // namespace cellctl::dashboard
