#pragma once
// What the cell did for an order, command by command, in sim time: the report's Gantt chart.

#include <string>
#include <vector>

namespace twin {

struct TimelineEntry {
  std::string resource, operation, part;
  std::string state;  // how it ended: "succeeded", "aborted", ...; "" while it runs
  double start = 0, end = 0;  // s of sim time
};

using Timeline = std::vector<TimelineEntry>;

}  // namespace twin
