#pragma once
// A plan as people read it: a table and the findings.

#include <ostream>

#include "twin/planning/assembly_planner.hpp"

namespace cellctl {

void print_plan(const twin::Product& product, const twin::Plan& plan, std::ostream& out);

}  // namespace cellctl
