#pragma once
// How a resource says that its process ended under a command (the process after it answers
// the command ABORTED with this in the reason), and how a commander recognises it: the work
// was not refused, the resource came back, and the order can be taken up again.

#include <string>

namespace fb {

inline std::string restarted_reason(const std::string& resource) {
  return resource + " restarted: its process ended with this command under way or queued";
}

inline bool says_restarted(const std::string& reason) {
  return reason.find(" restarted: its process ended") != std::string::npos;
}

}  // namespace fb
