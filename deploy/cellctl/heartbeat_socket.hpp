#pragma once
// The supervisor's end of services::Heartbeat: a unix datagram socket, named to the children
// by NOTIFY_SOCKET as systemd names its own, on which each beat's sender is known by its pid
// (the kernel's SCM_CREDENTIALS, as systemd reads them). Abstract (no file to leave behind),
// named after this process, so two cells on one host never share one.

#include <sys/types.h>

#include <chrono>
#include <map>
#include <set>
#include <string>

namespace cellctl {

class HeartbeatSocket {
 public:
  using Clock = std::chrono::steady_clock;
  // Binds "@agile-cell-heartbeat-<pid>"; throws std::runtime_error where it cannot.
  HeartbeatSocket();
  ~HeartbeatSocket();
  HeartbeatSocket(const HeartbeatSocket&) = delete;
  HeartbeatSocket& operator=(const HeartbeatSocket&) = delete;

  // The NOTIFY_SOCKET value for a child.
  const std::string& name() const { return name_; }
  // Names it in this process's environment (NOTIFY_SOCKET): every process started from here
  // on beats on it.
  void name_to_children() const;
  // Beats are kept for the pids watched only (any local process may send to the socket).
  void watch(pid_t pid);
  void forget(pid_t pid);
  // Reads what came (at most a bounded number of datagrams a call: a flood does not hold the
  // caller); when each watched pid that beat did so last.
  const std::map<pid_t, Clock::time_point>& beats();
  // Reads what came; for each watched pid that beat and then fell silent for longer than
  // `silence`, why it is taken for hung: "its heartbeat stopped 31 s ago (its loop is stuck)".
  std::map<pid_t, std::string> stopped(Clock::duration silence);
  // stopped() past a cell's `twin_watchdog` (s), each reason saying so.
  std::map<pid_t, std::string> past_twin_watchdog(double twin_watchdog);

 private:
  int fd_ = -1;
  std::string name_;
  std::set<pid_t> watched_;
  std::map<pid_t, Clock::time_point> last_beat_;
};

}  // namespace cellctl
