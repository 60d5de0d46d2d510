#pragma once
// The designer's report: one HTML file that opens from disk with no network. It holds the
// virtual assembly as an animated 3D view (three.js and its glTF loader, built into the
// program: twin/report/viewer), the steps with their insertion margins, the findings (a
// click shows the parts they name), the choices the links leave open, and for a cell run a
// Gantt chart of the resources over sim time.

#include <filesystem>
#include <string>

#include "twin/report/gltf_animation.hpp"
#include "twin/report/timeline.hpp"

namespace twin {

struct ReportOptions {
  AnimationOptions look;
  std::string title;  // what the report is of, e.g. the order's id; the product's name if empty
  Timeline timeline;  // a cell run's commands; empty for a plan alone
  std::string answer;  // a line for the top, the cell's answer (a quote's time and cost); may be empty
};

std::string html_report(const LoadedProduct& product, const Plan& plan, const ReportOptions& options = {});
// Throws std::runtime_error if it cannot write the file.
void write_html_report(const LoadedProduct& product, const Plan& plan, const std::filesystem::path& file,
                       const ReportOptions& options = {});

}  // namespace twin
