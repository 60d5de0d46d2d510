#pragma once
// The processes cellctl starts: spawned with their own argv, ended by their pid (SIGTERM,
// then SIGKILL after a grace time), their peak memory read from /proc. One started with
// `with_input` reads what write_input() sends on its standard input (a standby twin's order).

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace cellctl {

class Process {
 public:
  // `stdout_to`, `stderr_to`: files its output goes to (created, 0600), else cellctl's.
  Process(std::string name, const std::vector<std::string>& argv, const std::string& stdout_to = "",
          const std::string& stderr_to = "", bool with_input = false);
  ~Process();  // ends it if it still runs
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  const std::string& name() const { return name_; }
  void rename(std::string name) { name_ = std::move(name); }
  // All of `text` to its standard input; false when it cannot take it (it ended, or has none).
  bool write_input(const std::string& text);
  pid_t pid() const { return pid_; }
  // Its exit code once it ended by itself (-1 while it runs, 128+signal when killed).
  int poll();
  int wait();
  // SIGTERM, up to `grace`, then SIGKILL; its exit code.
  int stop(std::chrono::milliseconds grace = std::chrono::seconds(5));
  // SIGTERM and no wait (stop() several processes at once: terminate() each, then stop()).
  void terminate();
  // Peak resident memory so far (VmHWM), kB; 0 when unknown.
  long peak_rss_kb() const;

 private:
  std::string name_;
  pid_t pid_ = -1;
  int exit_code_ = -1;
  int input_ = -1;  // our end of its standard input
};

// Stops them all at once: SIGTERM to each, then each waited for up to `grace` (then SIGKILL).
void stop_all(const std::vector<Process*>& processes, std::chrono::milliseconds grace = std::chrono::seconds(5));

// The folder cellctl runs from: the other executables are beside it.
std::string executable_dir();

}  // namespace cellctl
