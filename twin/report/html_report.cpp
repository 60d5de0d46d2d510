#include "twin/report/html_report.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include <nlohmann/json.hpp>

#include "twin/report/viewer/viewer_assets.hpp"

namespace twin {
namespace {

std::string escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

// JSON inside <script>: "</" would end the element (a part named "</script>" must not).
std::string script_text(std::string text) {
  for (std::size_t at = 0; (at = text.find("</", at)) != std::string::npos; at += 3) text.replace(at, 2, "<\\/");
  return text;
}

std::string fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

std::string step_label(const Product& product, const PlanStep& step) {
  const std::string& part = product.parts()[step.part].name;
  if (!step.carried.empty()) return step_name(product, step);
  return step.subassembly.empty() ? part : step.subassembly + ": " + part;
}

std::string margin_cell(const PlanStep& step, const Plan& plan) {
  if (!step.margin_measured) return "<td>-</td>";
  if (!step.margin) return "<td>&gt; " + fixed(plan.margin_reach * 1000, 0) + "</td>";
  const Margin& m = *step.margin;
  const bool low = m.distance < plan.margin_threshold;
  return std::string("<td class=\"") + (low ? "low" : "") + "\" title=\"the " + escape(m.member) + " passes " +
         fixed(m.distance * 1000, 2) + " mm from " + escape(m.with) + " while " + escape(m.phase) + "\">" +
         fixed(m.distance * 1000, 2) + " " + escape(m.with) + (m.member == "part" ? "" : " (" + escape(m.member) + ")") +
         "</td>";
}

void steps_table(std::ostream& html, const Product& product, const Plan& plan) {
  html << "<table id=\"steps\"><thead><tr><th>step</th><th>part</th><th>type</th><th>direction</th><th>grasp</th>"
          "<th>path mm</th><th>margin mm</th><th>tries</th><th>result</th></tr></thead><tbody>\n";
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const PlanStep& step = plan.steps[i];
    const auto& part = product.parts()[step.part];
    html << "<tr data-step=\"" << i << "\"><td>" << i + 1 << "</td><td>" << escape(step_label(product, step))
         << "</td><td>" << escape(step.carried.empty() ? short_type_name(part.type) : "subassembly") << "</td><td>"
         << escape(step.trajectory.label) << "</td><td>" << escape(step.trajectory.grasp.label) << " ("
         << fixed(step.trajectory.grasp.opening * 1000, 1) << " mm)</td><td>" << fixed(step.trajectory.path_length() * 1000, 1)
         << "</td>" << margin_cell(step, plan) << "<td>" << step.failed.size() + 1 << "</td><td>"
         << escape(step_result(step)) << "</td></tr>\n";
  }
  html << "</tbody></table>\n";
}

void findings_list(std::ostream& html, const Plan& plan) {
  if (plan.findings.empty()) {
    html << "<p>None.</p>\n";
    return;
  }
  html << "<ol id=\"findings\">\n";
  for (std::size_t i = 0; i < plan.findings.size(); ++i) {
    const Finding& f = plan.findings[i];
    html << "<li class=\"finding\" data-finding=\"" << i << "\" tabindex=\"0\"><span class=\"kind kind-" << escape(f.kind)
         << "\">" << escape(f.kind) << "</span> " << escape(f.message) << "</li>\n";
  }
  html << "</ol>\n";
}

// Where the links left a choice: what they allowed and what the planner took.
void choices(std::ostream& html, const Product& product, const Plan& plan) {
  std::ostringstream rows;
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const PlanStep& step = plan.steps[i];
    if (step.allowed.size() < 2) continue;
    rows << "<tr><td>" << i + 1 << "</td><td>" << escape(product.parts()[step.part].name) << "</td><td>";
    for (std::size_t k = 0; k < step.allowed.size(); ++k) {
      rows << (k ? ", " : "") << escape(product.parts()[step.allowed[k]].name);
    }
    rows << "</td></tr>\n";
  }
  if (rows.str().empty()) {
    html << "<p>The links fix the order: at every step one part could go in.</p>\n";
    return;
  }
  html << "<p>At these steps the links allowed several parts; links between them would settle the order.</p>\n"
          "<table><thead><tr><th>step</th><th>chosen</th><th>allowed</th></tr></thead><tbody>\n"
       << rows.str() << "</tbody></table>\n";
}

// One bar per step: its margin (capped at the reach), the threshold as a line.
void margin_chart(std::ostream& html, const Plan& plan) {
  const double width = 24, height = 120, reach = std::max(plan.margin_reach, 1e-6);
  const double w = 40 + width * static_cast<double>(plan.steps.size());
  html << "<svg id=\"margin-chart\" width=\"" << w << "\" height=\"" << height + 30 << "\" role=\"img\">"
       << "<title>insertion margin per step, mm (capped at " << fixed(reach * 1000, 0) << ")</title>\n";
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const PlanStep& step = plan.steps[i];
    if (!step.margin_measured) continue;
    const double m = step.margin ? std::min(step.margin->distance, reach) : reach;
    const double h = std::max(1.0, height * m / reach);
    const bool low = step.margin && step.margin->distance < plan.margin_threshold;
    html << "<rect x=\"" << 40 + width * static_cast<double>(i) + 3 << "\" y=\"" << height - h << "\" width=\"" << width - 6
         << "\" height=\"" << h << "\" class=\"" << (low ? "bar low" : "bar") << "\"><title>step " << i + 1 << ": "
         << (step.margin ? fixed(step.margin->distance * 1000, 2) + " mm" : "more than " + fixed(reach * 1000, 0) + " mm")
         << "</title></rect><text x=\"" << 40 + width * (static_cast<double>(i) + 0.5) << "\" y=\"" << height + 14
         << "\" text-anchor=\"middle\">" << i + 1 << "</text>\n";
  }
  const double y = height - height * std::min(plan.margin_threshold, reach) / reach;
  html << "<line x1=\"36\" x2=\"" << w << "\" y1=\"" << y << "\" y2=\"" << y << "\" class=\"threshold\"/>"
       << "<text x=\"0\" y=\"" << y + 4 << "\">" << fixed(plan.margin_threshold * 1000, 1) << "</text>"
       << "<text x=\"0\" y=\"10\">" << fixed(reach * 1000, 0) << "</text></svg>\n";
}

// Resources down, sim time across; a bar per command, coloured by operation.
void gantt(std::ostream& html, const Timeline& timeline) {
  std::vector<std::string> resources;
  double begin = timeline.front().start, end = timeline.front().end;
  for (const auto& e : timeline) {
    if (std::find(resources.begin(), resources.end(), e.resource) == resources.end()) resources.push_back(e.resource);
    begin = std::min(begin, e.start);
    end = std::max(end, e.end);
  }
  std::sort(resources.begin(), resources.end());
  std::map<std::string, int> colour;
  for (const auto& e : timeline) colour.emplace(e.operation, static_cast<int>(colour.size()));
  const double left = 140, scale = end > begin ? 800 / (end - begin) : 1, row = 26;
  html << "<svg id=\"gantt-chart\" width=\"" << left + 860 << "\" height=\"" << row * static_cast<double>(resources.size()) + 30
       << "\" role=\"img\"><title>the order's commands per resource over sim time</title>\n";
  for (std::size_t r = 0; r < resources.size(); ++r) {
    html << "<text x=\"0\" y=\"" << row * static_cast<double>(r) + 17 << "\">" << escape(resources[r]) << "</text>\n";
  }
  for (const auto& e : timeline) {
    const auto r = static_cast<double>(std::find(resources.begin(), resources.end(), e.resource) - resources.begin());
    html << "<rect x=\"" << left + (e.start - begin) * scale << "\" y=\"" << row * r + 4 << "\" width=\""
         << std::max(1.0, (e.end - e.start) * scale) << "\" height=\"" << row - 8 << "\" class=\"op op-"
         << colour[e.operation] % 8 << (e.state == "succeeded" ? "" : " failed") << "\"><title>" << escape(e.operation)
         << (e.part.empty() ? "" : " " + escape(e.part)) << ": " << fixed(e.start, 1) << " to " << fixed(e.end, 1)
         << " s, " << escape(e.state.empty() ? "not ended" : e.state) << "</title></rect>\n";
  }
  const double axis = row * static_cast<double>(resources.size()) + 16;
  for (int k = 0; k <= 4; ++k) {
    html << "<text x=\"" << left + 200 * k << "\" y=\"" << axis << "\">" << fixed(begin + (end - begin) * k / 4, 1) << " s</text>\n";
  }
  html << "</svg>\n<p class=\"legend\">";
  for (const auto& [operation, c] : colour) html << "<span class=\"op-key op-" << c % 8 << "\"></span>" << escape(operation) << " ";
  html << "</p>\n";
}

nlohmann::json viewer_data(const Product& product, const Plan& plan, const GltfAnimation& animation) {
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const PlanStep& step = plan.steps[i];
    nlohmann::json parts = {product.parts()[step.part].name};
    for (PartIndex p : step.carried) parts.push_back(product.parts()[p].name);
    steps.push_back({{"label", step_label(product, step)},
                     {"parts", parts},
                     {"start", i < animation.steps.size() ? animation.steps[i].first : 0.0},
                     {"end", i < animation.steps.size() ? animation.steps[i].second : 0.0}});
  }
  nlohmann::json findings = nlohmann::json::array();
  for (const Finding& f : plan.findings) {
    // The step a finding is about, where it names one ("step 3 ..."), for the caption.
    int step = -1;
    if (f.message.rfind("step ", 0) == 0) step = std::atoi(f.message.c_str() + 5) - 1;
    findings.push_back({{"kind", f.kind}, {"message", f.message}, {"parts", f.parts}, {"step", step}});
  }
  return {{"steps", steps}, {"findings", findings}};
}

}  // namespace

std::string html_report(const LoadedProduct& loaded, const Plan& plan, const ReportOptions& options) {
  const Product& product = loaded.product;
  const GltfAnimation animation = gltf_animation(loaded, plan, options.look);
  const std::string title = options.title.empty() ? product.name() : options.title;
  const std::size_t placed = plan.parts_placed();

  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" << escape(title)
       << ": virtual assembly</title>\n<style>\n" << viewer::report_css() << "</style></head>\n<body>\n<header><h1>"
       << escape(product.name()) << (options.title.empty() ? "" : " <small>" + escape(options.title) + "</small>")
       << "</h1>\n<p class=\"summary " << (plan.complete ? "complete" : "incomplete") << "\">"
       << (plan.complete ? "Complete" : "INCOMPLETE") << ": " << placed << " of " << product.parts().size()
       << " parts in " << plan.steps.size() << " steps"
       << (plan.orientation == "as finished" ? "" : ", built " + escape(plan.orientation) + " (and delivered so)")
       << "; sequence " << escape(plan.sequence_planner) << ", path "
       << escape(plan.path_planner) << "; " << plan.backtracks << " backtracks; least insertion margin "
       << fixed(least_margin(plan.steps, plan.margin_reach) * 1000, 2) << " mm; " << plan.findings.size()
       << " findings.</p>\n"
       << (options.answer.empty() ? "" : "<p class=\"answer\">" + escape(options.answer) + "</p>\n")
       << "</header>\n<main>\n"
       << "<section id=\"viewer\"><div id=\"stage\"><canvas id=\"view\" width=\"960\" height=\"540\"></canvas>"
          "<div id=\"caption\"></div><div id=\"viewer-error\" hidden></div></div>\n"
          "<div id=\"controls\"><button id=\"play\" type=\"button\">Pause</button> "
          "<input id=\"time\" type=\"range\" min=\"0\" max=\"1000\" value=\"0\"> <span id=\"clock\"></span> "
          "<button id=\"overview\" type=\"button\">Whole product</button></div></section>\n"
       << "<section><h2>Findings</h2>\n";
  findings_list(html, plan);
  html << "</section>\n<section><h2>Steps</h2>\n";
  steps_table(html, product, plan);
  html << "</section>\n<section><h2>Insertion margins</h2>\n<p>The least room the part, or the gripper holding it, "
          "had on its way in, in mm; steps under the threshold (" << fixed(plan.margin_threshold * 1000, 1)
       << " mm) in red.</p>\n";
  margin_chart(html, plan);
  html << "</section>\n<section><h2>Open order</h2>\n";
  choices(html, product, plan);
  html << "</section>\n";
  if (!options.timeline.empty()) {
    html << "<section><h2>The cell's run</h2>\n";
    gantt(html, options.timeline);
    html << "</section>\n";
  }
  html << "</main>\n<script type=\"application/json\" id=\"gltf\">" << script_text(animation.text)
       << "</script>\n<script type=\"application/json\" id=\"report-data\">"
       << script_text(viewer_data(product, plan, animation).dump()) << "</script>\n"
       << "<script>\n" << viewer::three_js() << "\n</script>\n<script>\n" << viewer::gltf_loader_js()
       << "\n</script>\n<script>\n" << viewer::orbit_controls_js() << "\n</script>\n<script>\n" << viewer::report_js()
       << "\n</script>\n</body></html>\n";
  return html.str();
}

void write_html_report(const LoadedProduct& product, const Plan& plan, const std::filesystem::path& file,
                       const ReportOptions& options) {
  std::ofstream out(file);
  out << html_report(product, plan, options);
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace twin
