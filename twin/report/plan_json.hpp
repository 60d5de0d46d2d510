#pragma once
// The plan as programs read it: schema "agile-cell/plan" version 1 (docs/cli.md). Written by
// `cellctl plan --json` and by the twin at the end of an order.

#include <nlohmann/json.hpp>

#include "twin/planning/assembly_planner.hpp"

namespace twin {

nlohmann::json plan_json(const Product& product, const Plan& plan);

}  // namespace twin
