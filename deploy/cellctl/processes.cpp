#include "deploy/cellctl/processes.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "services/node/started_by.hpp"

extern char** environ;

namespace cellctl {
namespace {

int exit_code_of(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

}  // namespace

Process::Process(std::string name, const std::vector<std::string>& argv, const std::string& stdout_to,
                 const std::string& stderr_to, bool with_input)
    : name_(std::move(name)) {
  std::vector<std::string> copy = argv;
  std::vector<char*> args;
  for (auto& a : copy) args.push_back(a.data());
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // A socket, not a pipe: a write to one whose reader died fails with EPIPE and no SIGPIPE
  // (MSG_NOSIGNAL). Both ends close on exec; the child's copy on its stdin does not.
  int input[2] = {-1, -1};
  if (with_input && ::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, input) != 0) {
    posix_spawn_file_actions_destroy(&actions);
    throw std::runtime_error("cannot start " + argv[0] + ": no socket for its input");
  }
  if (with_input) posix_spawn_file_actions_adddup2(&actions, input[1], STDIN_FILENO);
  for (const auto& [fd, file] : {std::pair{STDOUT_FILENO, &stdout_to}, std::pair{STDERR_FILENO, &stderr_to}}) {
    if (!file->empty()) posix_spawn_file_actions_addopen(&actions, fd, file->c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  }
  // The child's environment: ours, and who started it (services::stop_with_parent).
  std::vector<std::string> variables;
  const std::string parent = std::string(services::kStartedByVariable) + "=";
  for (char** v = environ; *v; ++v) {
    if (std::string(*v).rfind(parent, 0) != 0) variables.emplace_back(*v);
  }
  variables.push_back(parent + std::to_string(::getpid()));
  std::vector<char*> environment;
  for (auto& v : variables) environment.push_back(v.data());
  environment.push_back(nullptr);
  // Each process starts with SIGPIPE as the system has it, whatever cellctl ignores (the dashboard).
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF);
  const int spawned = posix_spawn(&pid_, args[0], &actions, &attributes, args.data(), environment.data());
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&actions);
  if (with_input) {
    ::close(input[1]);
    input_ = input[0];
  }
  if (spawned != 0) {
    if (input_ >= 0) ::close(input_);
    pid_ = -1;
    throw std::runtime_error("cannot start " + argv[0]);
  }
}

Process::~Process() {
  if (pid_ > 0 && exit_code_ < 0) stop(std::chrono::milliseconds(2000));
  if (input_ >= 0) ::close(input_);
}

bool Process::write_input(const std::string& text) {
  for (std::size_t sent = 0; sent < text.size();) {
    const ssize_t n = input_ < 0 ? -1 : ::send(input_, text.data() + sent, text.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

int Process::poll() {
  if (exit_code_ >= 0 || pid_ <= 0) return exit_code_;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) exit_code_ = exit_code_of(status);
  return exit_code_;
}

int Process::wait() {
  if (exit_code_ >= 0) return exit_code_;
  int status = 0;
  if (::waitpid(pid_, &status, 0) == pid_) exit_code_ = exit_code_of(status);
  return exit_code_;
}

int Process::stop(std::chrono::milliseconds grace) {
  if (poll() >= 0) return exit_code_;
  ::kill(pid_, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + grace;
  while (std::chrono::steady_clock::now() < deadline) {
    if (poll() >= 0) return exit_code_;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid_, SIGKILL);
  return wait();
}

void Process::terminate() {
  if (poll() < 0) ::kill(pid_, SIGTERM);
}

void stop_all(const std::vector<Process*>& processes, std::chrono::milliseconds grace) {
  for (Process* p : processes) p->terminate();
  const auto deadline = std::chrono::steady_clock::now() + grace;
  for (Process* p : processes) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    p->stop(std::max(left, std::chrono::milliseconds(0)));
  }
}

long Process::peak_rss_kb() const {
  std::ifstream status("/proc/" + std::to_string(pid_) + "/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
  }
  return 0;
}

std::string executable_dir() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path().string();
}

}  // namespace cellctl
