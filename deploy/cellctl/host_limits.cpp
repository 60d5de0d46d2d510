#include "deploy/cellctl/host_limits.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <limits>

namespace cellctl {
namespace {

long read_first_number(const std::string& file, const std::string& key = "") {
  std::ifstream in(file);
  for (std::string word; in >> word;) {
    if (key.empty()) return std::stol(word);
    if (word == key) {
      long value = 0;
      in >> value;
      return value;
    }
  }
  return 0;
}

long soft_limit(int resource) {
  rlimit r{};
  if (::getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return std::numeric_limits<long>::max();
  return static_cast<long>(r.rlim_cur);
}

}  // namespace

HostLimits read_host_limits() {
  HostLimits h;
  h.memory_mb = read_first_number("/proc/meminfo", "MemTotal:") / 1024;
  h.threads = std::min(soft_limit(RLIMIT_NPROC), read_first_number("/proc/sys/kernel/threads-max"));
  h.open_files = soft_limit(RLIMIT_NOFILE);
  return h;
}

std::size_t participants_here(const CellConfig& cell, std::size_t processes_here, std::size_t twins) {
  return processes_here + twins + static_cast<std::size_t>(cell.standby_twins) + 1;
}

std::size_t participant_ports(int domain) {
  const long first = 7400 + 250L * domain + 10;
  const long by_port = (65535 - first - 1) / 2 + 1;
  return static_cast<std::size_t>(std::clamp(by_port, 0L, 120L));
}

std::vector<std::string> limit_problems(const CellConfig& cell, std::size_t processes_here, std::size_t twins,
                                        const HostLimits& host) {
  std::vector<std::string> out;
  const std::size_t participants = participants_here(cell, processes_here, twins);
  const std::string counted = std::to_string(participants) + " DDS participants on this host (" +
                              std::to_string(processes_here) + " processes, " + std::to_string(twins) + " twins at once, " +
                              std::to_string(cell.standby_twins) + " standing by, cellctl)";
  if (cell.simple_discovery && participants > kSimpleDiscoveryParticipants) {
    out.push_back(counted + " pass the " + std::to_string(kSimpleDiscoveryParticipants) +
                  " that simple discovery finds: set `discovery: server`, or lower max_twins");
  }
  const std::size_t ports = std::min<std::size_t>(participant_ports(cell.domain), kServerDiscoveryParticipants);
  if (participants > ports) {
    out.push_back(counted + " pass the " + std::to_string(ports) + " Fast DDS gives ports to on domain " +
                  std::to_string(cell.domain) + ": lower max_twins" + (ports < kServerDiscoveryParticipants ? ", or use a lower domain" : ""));
  }
  const long memory = static_cast<long>(processes_here) * kCellProcessMb + static_cast<long>(twins) * kTwinPeakMb +
                      cell.standby_twins * kStandbyTwinMb;
  if (host.memory_mb > 0 && memory > host.memory_mb) {
    out.push_back("the cell's processes and " + std::to_string(twins) + " twins at once may need " + std::to_string(memory) +
                  " MB (" + std::to_string(kTwinPeakMb) + " MB a twin at work); the host has " + std::to_string(host.memory_mb) +
                  " MB: lower max_twins");
  }
  const long threads = static_cast<long>(participants) * kThreadsPerProcess;
  if (host.threads > 0 && threads > host.threads) {
    out.push_back("the cell may run " + std::to_string(threads) + " threads (" + std::to_string(kThreadsPerProcess) +
                  " a process); this user may run " + std::to_string(host.threads) + " (ulimit -u): lower max_twins");
  }
  const long files = kOpenFilesOfUp + 2 * static_cast<long>(participants);
  if (host.open_files > 0 && files > host.open_files) {
    out.push_back("cellctl up may hold " + std::to_string(files) + " open files; it may open " +
                  std::to_string(host.open_files) + " (ulimit -n): raise it, or lower max_twins");
  }
  return out;
}

}  // namespace cellctl
