#include "deploy/cellctl/quote_answer.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

namespace cellctl {

namespace fs = std::filesystem;
using nlohmann::json;

json read_quote(const fs::path& file, const std::string& order, std::string& why) {
  std::ifstream in(file);
  if (!in) return why = "no quote.json came back", json();
  const json q = json::parse(
      in, [](int depth, json::parse_event_t, json&) { return depth <= 8; }, false);
  const auto text = [](const json& j, const char* key) -> const std::string* {
    return j.contains(key) && j[key].is_string() ? &j[key].get_ref<const std::string&>() : nullptr;
  };
  const auto number = [](const json& j, const char* group, const char* key) {
    if (!j.contains(group) || !j[group].is_object() || !j[group].contains(key) || !j[group][key].is_number()) return -1.0;
    const double v = j[group][key].get<double>();
    return std::isfinite(v) && v >= 0 ? v : -1.0;
  };
  const std::string* schema = q.is_object() ? text(q, "schema") : nullptr;
  if (!schema || *schema != "agile-cell/quote" || !q.contains("feasible") || !q["feasible"].is_boolean()) {
    return why = file.string() + " is not a quote (schema agile-cell/quote)", json();
  }
  if (!text(q, "order") || *text(q, "order") != order) {
    return why = file.string() + " is not the answer to this request (order " + order + ")", json();
  }
  json out = {{"schema", "agile-cell/quote"}, {"order", order}, {"feasible", q["feasible"].get<bool>()}};
  json findings = json::array();
  if (q.contains("findings") && q["findings"].is_array()) {
    for (const auto& f : q["findings"]) {
      if (f.is_object() && text(f, "kind") && text(f, "message")) findings.push_back({{"kind", *text(f, "kind")}, {"message", *text(f, "message")}});
    }
  }
  out["findings"] = findings;
  if (!out["feasible"].get<bool>()) {
    out["reason"] = text(q, "reason") ? *text(q, "reason") : std::string("(the cell gave no reason)");
    return out;
  }
  for (const char* key : {"makespan", "wait", "station", "robot"}) {
    if ((out["time_s"][key] = number(q, "time_s", key)).get<double>() < 0) {
      return why = file.string() + ": time_s." + key + " is not a number >= 0", json();
    }
  }
  for (const char* key : {"setup", "station", "robot", "total"}) {
    if ((out["cost"][key] = number(q, "cost", key)).get<double>() < 0) {
      return why = file.string() + ": cost." + key + " is not a number >= 0", json();
    }
  }
  out["cost"]["currency"] = q.contains("cost") && q["cost"].is_object() && text(q["cost"], "currency") ? *text(q["cost"], "currency") : "";
  out["station"] = text(q, "station") ? *text(q, "station") : "";
  out["robot"] = text(q, "robot") ? *text(q, "robot") : "";
  return out;
}

std::string quote_submission_id(const std::string& product) {
  std::string stem = fs::path(product).stem().string().substr(0, 32);
  for (char& c : stem) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '-';
  }
  std::random_device random;
  char suffix[16];
  std::snprintf(suffix, sizeof suffix, "%08x", static_cast<unsigned>(random()));
  return "quote-" + stem + "-" + suffix;
}

}  // namespace cellctl
