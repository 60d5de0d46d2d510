// libFuzzer target: what reaches the cell's dashboard from the network (deploy/cellctl/
// dashboard_routes.hpp). An input whose first byte is even is a raw HTTP request, parsed by
// cpp-httplib and answered by the dashboard's gate and routes; one whose first byte is odd is
// the body of the operator's upload (a product's zip, with the token), unpacked, its
// description read and its order stored. The token is a fixed one here, so that requests can
// carry it. Any input may be refused; none may crash, hang or leak.
//   fuzz_dashboard_requests CORPUS_DIR [seed dirs...] -max_total_time=60

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/dashboard_routes.hpp"  // and httplib

namespace {

// A connection whose request is the input and whose answer goes nowhere (bounded).
class FuzzedStream : public httplib::Stream {
 public:
  explicit FuzzedStream(std::string_view request) : request_(request) {}
  bool is_readable() const override { return true; }
  bool is_writable() const override { return written_ < kMaxAnswer; }
  ssize_t read(char* ptr, size_t size) override {
    const std::size_t n = std::min(size, request_.size());
    std::copy_n(request_.data(), n, ptr);
    request_.remove_prefix(n);
    return static_cast<ssize_t>(n);
  }
  ssize_t write(const char*, size_t size) override {
    if (written_ >= kMaxAnswer) return -1;
    written_ += size;
    return static_cast<ssize_t>(size);
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = "127.0.0.1";
    port = 40000;
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    ip = "127.0.0.1";
    port = 8080;
  }
  socket_t socket() const override { return INVALID_SOCKET; }

 private:
  static constexpr std::size_t kMaxAnswer = 64u << 20;
  std::string_view request_;
  std::size_t written_ = 0;
};

// The server's own request handling, one request at a time.
class FuzzedServer : public httplib::Server {
 public:
  void answer(std::string_view request) {
    FuzzedStream stream(request);
    bool closed = false;
    process_request(stream, true, closed, nullptr);
  }
};

const std::string kToken(48, 'a');

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path state = "/tmp/fuzz-dashboard-" + std::to_string(::getpid());
  static cellctl::CellConfig cell = [] {
    cellctl::CellConfig c;
    c.state_dir = state;
    c.desk.max_order_mb = 4;
    return c;
  }();
  static cellctl::DashboardRoutes routes(cell, kToken);
  static FuzzedServer* server = [] {
    auto* s = new FuzzedServer;  // lives as long as the process
    routes.install(*s);
    return s;
  }();
  if (size == 0) return 0;
  const std::string_view input(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] % 2 == 0) {
    server->answer(input);
  } else {
    server->answer("POST /orders?order=fuzzed HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nAuthorization: Bearer " + kToken +
                  "\r\nContent-Type: application/zip\r\nContent-Length: " + std::to_string(input.size()) + "\r\n\r\n" +
                  std::string(input));
  }
  // An order that was taken stays in the state: the next input starts from none.
  if (std::filesystem::exists(state / "uploads")) std::filesystem::remove_all(state);
  return 0;
}
