#pragma once
// A process a test starts, and always ends: stop() sends SIGTERM and reaps it; the
// destructor kills (SIGKILL) and reaps whatever is still running.

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace test {

// Removes the shared-memory segments of Fast DDS processes that died without cleaning up
// (killed hard); stale segments break discovery of new processes. Segments of live
// processes are left alone, so tests running in parallel are safe.
inline void clean_stale_dds_segments() {
  if (std::system("fastdds shm clean >/dev/null 2>&1") != 0) {
    // Without the tool nothing is cleaned; the test still runs and says so if it fails.
  }
}

class ChildProcess {
 public:
  // `output`: a file that takes its stdout and stderr (empty: the test's own).
  explicit ChildProcess(std::vector<std::string> argv, const std::string& output = "") {
    std::vector<char*> args;
    for (auto& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (!output.empty()) {
      posix_spawn_file_actions_addopen(&actions, 1, output.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      posix_spawn_file_actions_adddup2(&actions, 1, 2);
    }
    // A process group of its own, whose leader's parent (this test) is in another group of the
    // session: the group is never orphaned while the test runs. In an orphaned group, the
    // exit of any member sends SIGHUP to all when one is stopped: a test's SIGSTOPped (hung)
    // process was so ended by its neighbours' exits where ctest's own group was orphaned
    // (ctest started in the background by a shell that has left).
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setpgroup(&attributes, 0);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    const int failed = posix_spawn(&pid_, args[0], &actions, &attributes, args.data(), environ);
    posix_spawnattr_destroy(&attributes);
    posix_spawn_file_actions_destroy(&actions);
    if (failed != 0) throw std::runtime_error("cannot start " + argv[0]);
  }
  // A copy of this process that runs `body` and exits with what it returns (1 if it throws).
  // Fork only from a test that has started no threads.
  explicit ChildProcess(const std::function<int()>& body) {
    std::fflush(nullptr);  // or the child writes what is buffered again
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("cannot fork");
    if (pid_ == 0) {
      int code = 1;
      try {
        code = body();
      } catch (...) {
      }
      ::_exit(code);
    }
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }

  // Whether it has not ended (one that ended is reaped).
  bool running() {
    if (pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == pid_) pid_ = -1;
    return pid_ > 0;
  }

  // SIGKILL: the process gets no chance to say goodbye (a crash, a power cut).
  void kill_hard() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

  // Waits up to `timeout` for it to end by itself; its exit code, or -1 (then it is stopped:
  // SIGTERM first, so that a process that started others can end them).
  int wait_for_exit(std::chrono::milliseconds timeout) {
    const int code = reap_within(timeout);
    if (pid_ > 0) stop();
    return code;
  }

  // SIGTERM, then waits up to `timeout` for it to exit; its exit code, or -1 if it had to
  // be killed.
  int stop(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    if (pid_ <= 0) return -1;  // reaped already; kill(-1) would signal every process
    ::kill(pid_, SIGTERM);
    return reap_within(timeout);  // if still running: the destructor kills it
  }

 private:
  // Its exit code once it ended within `timeout` (pid_ then -1), else -1.
  int reap_within(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

  pid_t pid_ = -1;
};

}  // namespace test
