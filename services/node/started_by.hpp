#pragma once
// The environment variable in which cellctl tells each process it starts its own pid
// (deploy/cellctl/processes.cpp): a process whose starter ended before the process asked to
// end with it (services::stop_with_parent) ends at once.

namespace services {

constexpr const char* kStartedByVariable = "AGILE_CELL_STARTED_BY";

}  // namespace services
