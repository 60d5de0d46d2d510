#pragma once
// What one host allows a cell, and what a deployment needs of it at most: DDS participants
// (simple discovery finds 32 per host; Fast DDS's ports give each domain 120), memory for
// its twins, threads, and cellctl up's open files. cellctl refuses a deployment that would
// pass one, naming the key to change, instead of a cell that falls apart under its orders.
// The figures per process are measured (docs/performance.md, "Limits of one host").

#include <cstddef>
#include <string>
#include <vector>

#include "deploy/cellctl/cell_config.hpp"

namespace cellctl {

constexpr int kServerDiscoveryParticipants = 116;  // Fast DDS's 120 participant ids per domain, less cellctl's commands
constexpr long kTwinPeakMb = 70;         // a twin at work (the largest of 20 mixed orders: 68-71 MB)
constexpr long kStandbyTwinMb = 29;      // an idle standby twin
constexpr long kCellProcessMb = 150;     // cell-sim with 20 orders' scenes (141 MB); the others stay below 50
constexpr long kThreadsPerProcess = 16;  // 7-9 counted in each process of an idle cell, twice that for a margin
constexpr long kOpenFilesOfUp = 64;      // cellctl up's own (DDS sockets, the database), and 2 per child

struct HostLimits {
  long memory_mb = 0;   // MemTotal
  long threads = 0;     // what this user may run: RLIMIT_NPROC, at most kernel.threads-max
  long open_files = 0;  // RLIMIT_NOFILE (soft) of cellctl
};
HostLimits read_host_limits();

// The participants on this host at most: its processes, the twins, cellctl up's own.
std::size_t participants_here(const CellConfig& cell, std::size_t processes_here, std::size_t twins);
// The highest participant count Fast DDS gives ports to on the cell's domain (7400 + 250 x
// domain + 10 + 2 x id + 1 must stay a port, and within the domain's 250).
std::size_t participant_ports(int domain);

// Each limit that `twins` twins at once (and standby_twins) beside the processes here would
// pass, as a sentence with the key to change; none: the deployment fits the host.
std::vector<std::string> limit_problems(const CellConfig& cell, std::size_t processes_here, std::size_t twins,
                                        const HostLimits& host);

}  // namespace cellctl
