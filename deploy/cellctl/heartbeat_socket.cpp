#include "deploy/cellctl/heartbeat_socket.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string_view>

namespace cellctl {
namespace {

// sd_notify's messages are lines of KEY=VALUE.
bool has_line(std::string_view message, std::string_view line) {
  for (std::size_t at = 0; at <= message.size();) {
    const std::size_t end = std::min(message.find('\n', at), message.size());
    if (message.substr(at, end - at) == line) return true;
    at = end + 1;
  }
  return false;
}

}  // namespace

HeartbeatSocket::HeartbeatSocket() : name_("@agile-cell-heartbeat-" + std::to_string(::getpid())) {
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("heartbeat socket: ") + std::strerror(errno));
  const int on = 1;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path + 1, name_.data() + 1, name_.size() - 1);  // sun_path[0] = 0: abstract
  const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name_.size());
  if (::setsockopt(fd_, SOL_SOCKET, SO_PASSCRED, &on, sizeof on) != 0 ||
      ::bind(fd_, reinterpret_cast<const sockaddr*>(&address), length) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("heartbeat socket " + name_ + ": " + why);
  }
}

HeartbeatSocket::~HeartbeatSocket() { ::close(fd_); }

void HeartbeatSocket::watch(pid_t pid) {
  watched_.insert(pid);
  last_beat_.erase(pid);  // a beat of an earlier process with its pid
}

void HeartbeatSocket::forget(pid_t pid) {
  watched_.erase(pid);
  last_beat_.erase(pid);
}

const std::map<pid_t, HeartbeatSocket::Clock::time_point>& HeartbeatSocket::beats() {
  char text[256];
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(ucred))];
  // A cell's processes send two a second each; past 4096 datagrams a call, the rest wait for
  // the next call (a flood from a stranger does not hold up the supervisor).
  for (int read = 0; read < 4096; ++read) {
    iovec io{text, sizeof text};
    msghdr message{};
    message.msg_iov = &io;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd_, &message, MSG_DONTWAIT | MSG_CMSG_CLOEXEC);
    if (n < 0) break;  // nothing more (EAGAIN), or nothing to be done about it
    const cmsghdr* c = CMSG_FIRSTHDR(&message);
    if (!c || c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_CREDENTIALS) continue;
    ucred sender{};
    std::memcpy(&sender, CMSG_DATA(c), sizeof sender);
    if (watched_.count(sender.pid) && has_line({text, static_cast<std::size_t>(n)}, "WATCHDOG=1")) {
      last_beat_[sender.pid] = Clock::now();
    }
  }
  return last_beat_;
}

void HeartbeatSocket::name_to_children() const { ::setenv("NOTIFY_SOCKET", name_.c_str(), 1); }

std::map<pid_t, std::string> HeartbeatSocket::past_twin_watchdog(double twin_watchdog) {
  auto out = stopped(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(twin_watchdog)));
  for (auto& [pid, why] : out) why += ", past twin_watchdog " + std::to_string(std::lround(twin_watchdog)) + " s";
  return out;
}

std::map<pid_t, std::string> HeartbeatSocket::stopped(Clock::duration silence) {
  const auto now = Clock::now();
  std::map<pid_t, std::string> out;
  for (const auto& [pid, at] : beats()) {
    if (now - at <= silence) continue;
    const auto ago = std::chrono::duration_cast<std::chrono::seconds>(now - at).count();
    out[pid] = "its heartbeat stopped " + std::to_string(ago) + " s ago (its loop is stuck)";
  }
  return out;
}

}  // namespace cellctl
