#pragma once
// What the process tests share: a scratch folder per test, reading a log, running cellctl to
// its end with a bound, and the resident memory of a process.

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/child_process.hpp"

namespace test {

// The example product and the resources of the default cell (deploy/cells/default.yaml).
inline const std::string kLegoTower = std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml";
inline const std::vector<std::string> kDefaultCellResources{"station-1", "arm-1", "mobile-robot-1", "buffer-1", "buffer-2"};

inline std::filesystem::path scratch(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("agile-cell-test-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The last `count` lines of a file: where a failure's message is cut short, what came last
// (where a process stopped) is what tells.
inline std::string last_lines(const std::filesystem::path& file, std::size_t count) {
  const std::string text = read_text(file);
  std::size_t at = text.size();
  if (at > 0 && text[at - 1] == '\n') --at;  // the last line's end
  for (std::size_t n = 0; n < count; ++n) {
    if (at == 0 || (at = text.rfind('\n', at - 1)) == std::string::npos) return text;
  }
  return text.substr(at + 1);
}

// `cellctl ARGS...` to its end (bounded), output in `log`; its exit code.
inline int cellctl(std::vector<std::string> args, const std::filesystem::path& log,
                   std::chrono::seconds timeout = std::chrono::seconds(120)) {
  args.insert(args.begin(), CELLCTL_EXE);
  ChildProcess p(args, log.string());
  return p.wait_for_exit(timeout);
}

// The lines of a log that say what went wrong ("error: ...", a watchdog's, an exception's),
// for a failed check to show first: CI shows only the start of a long message.
inline std::string error_lines(const std::string& log) {
  std::istringstream lines(log);
  std::string out;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("error") != std::string::npos || line.find("FAILED") != std::string::npos ||
        line.find("ABORTED") != std::string::npos || line.find("disappeared") != std::string::npos) {
      out += line + '\n';
    }
  }
  return out.empty() ? "(no error line)" : out;
}

// Waits until the text shows up in the file (a process's log).
// `from`: where in the file to look from (its size before what the test waits for began: a
// line of the same words from earlier, a restart at start-up, does not count).
inline bool appears(const std::filesystem::path& file, const std::string& text,
                    std::chrono::seconds timeout = std::chrono::seconds(30), std::size_t from = 0) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (read_text(file).find(text, from) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// Whether the process runs: it exists and is not a zombie (an orphan that ended waits to be
// reaped by whoever adopted it).
inline bool is_running(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

// VmRSS of a process in kB, 0 when it is gone.
inline long rss_kb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return 0;
}

// The children of `parent` by their command's file name (cell processes under `cellctl up`).
inline std::vector<std::pair<std::string, pid_t>> children_of(pid_t parent) {
  std::vector<std::pair<std::string, pid_t>> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    const auto close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    char state;
    pid_t ppid = 0;
    rest >> state >> ppid;
    if (ppid != parent) continue;
    const auto open = line.find('(');
    const std::string command = line.substr(open + 1, close - open - 1);
    // clang's sanitizer runtimes start it to name the frames of a report or a suppression:
    // not one of the cell's processes.
    if (command == "llvm-symbolizer") continue;
    out.push_back({command, static_cast<pid_t>(std::stol(name))});
  }
  return out;
}

}  // namespace test

namespace test {

// The child of `parent` whose command line has `argument` (a resource id), or 0.
inline pid_t child_with_argument(pid_t parent, const std::string& argument) {
  for (const auto& [name, pid] : children_of(parent)) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
    std::string arg;
    while (std::getline(in, arg, '\0')) {
      if (arg == argument) return pid;
    }
  }
  return 0;
}

}  // namespace test
