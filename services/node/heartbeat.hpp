#pragma once
// Tells the process's supervisor that its event loops still turn, by systemd's notify
// protocol (sd_notify(3)): a "WATCHDOG=1" datagram to the unix socket that NOTIFY_SOCKET
// names. cellctl up ends and restarts a cell process that falls silent, as systemd does with
// WatchdogSec=; under systemd the same beats feed WatchdogSec. Without NOTIFY_SOCKET, beat()
// does nothing.
//
// Why: a process whose DDS participant stays alive while its own threads are stuck is not
// seen as gone by anyone (Fast DDS 2.9.1's deadlock between a writer's matched_reader_remove
// and its flow controller, fixed upstream in eProsima/Fast-DDS#5432, hung cell-sim and a
// whole cell with it).

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace services {

class Heartbeat {
 public:
  Heartbeat() {
    const char* path = std::getenv("NOTIFY_SOCKET");
    const std::size_t size = path ? std::strlen(path) : 0;
    if (size == 0 || size >= sizeof(address_.sun_path)) return;
    address_.sun_family = AF_UNIX;
    std::memcpy(address_.sun_path, path, size);
    if (path[0] == '@') address_.sun_path[0] = '\0';  // an abstract socket (no file)
    length_ = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + size);
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (const char* usec = std::getenv("WATCHDOG_USEC")) {  // systemd's: beat at half its interval
      const long long half = std::atoll(usec) / 2;
      if (half > 0 && half < every_.count() * 1000) every_ = std::chrono::milliseconds(half / 1000);
    }
  }
  ~Heartbeat() {
    if (fd_ >= 0) ::close(fd_);
  }
  Heartbeat(const Heartbeat&) = delete;
  Heartbeat& operator=(const Heartbeat&) = delete;

  // Called from every turn of the process's loop: at most one datagram an interval, never
  // blocking (a supervisor that reads none does not stall the process).
  void beat() {
    if (fd_ < 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < every_) return;
    last_ = now;
    static constexpr char kMessage[] = "WATCHDOG=1";
    ::sendto(fd_, kMessage, sizeof kMessage - 1, MSG_NOSIGNAL | MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&address_),
             length_);
  }

 private:
  int fd_ = -1;
  sockaddr_un address_{};
  socklen_t length_ = 0;
  std::chrono::milliseconds every_{500};
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace services
