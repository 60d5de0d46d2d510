#pragma once
// A plan as people and programs read it: a table and findings, and a JSON document.

#include <ostream>

#include <nlohmann/json.hpp>

#include "twin/planning/assembly_planner.hpp"

namespace cellctl {

// Schema "agile-cell/plan" version 1, documented in docs/cli.md.
nlohmann::json plan_json(const twin::Product& product, const twin::Plan& plan);
void print_plan(const twin::Product& product, const twin::Plan& plan, std::ostream& out);

}  // namespace cellctl
