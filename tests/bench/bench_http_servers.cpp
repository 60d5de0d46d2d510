// The dashboard's HTTP server, measured against the other one Debian packages in C++ with
// nothing more to build: cpp-httplib (the dashboard's) and civetweb. Both serve the same body
// (as large as the dashboard's /state with a few orders) on loopback, in this process; a
// cpp-httplib client asks them in turns, so both see the same machine:
//  - one client, keep-alive: each request's round trip, p50 and p99;
//  - 8 clients at once, keep-alive: requests answered per second.
// Run on a quiet machine: build/release/bin/bench_http_servers [--requests 5000] [--body-kb 20]

#include <civetweb.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <httplib.h>

namespace {

using Clock = std::chrono::steady_clock;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * v.size()))];
}

struct HttplibServer {
  httplib::Server server;
  std::thread thread;
  int port = 0;
  explicit HttplibServer(const std::string& body) {
    server.set_tcp_nodelay(true);  // as the dashboard's (dashboard.cpp)
    server.Get("/state", [&body](const httplib::Request&, httplib::Response& res) { res.set_content(body, "application/json"); });
    port = server.bind_to_any_port("127.0.0.1");
    thread = std::thread([this] { server.listen_after_bind(); });
    while (!server.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ~HttplibServer() {
    server.stop();
    thread.join();
  }
};

struct CivetwebServer {
  mg_context* context = nullptr;
  int port = 0;
  const std::string& body;
  explicit CivetwebServer(const std::string& b) : body(b) {
    mg_init_library(0);
    const char* options[] = {"listening_ports", "127.0.0.1:0", "num_threads", "8", "enable_keep_alive", "yes",
                             "tcp_nodelay", "1", nullptr};
    context = mg_start(nullptr, nullptr, options);
    if (!context) throw std::runtime_error("civetweb did not start");
    mg_set_request_handler(context, "/state", &CivetwebServer::answer, this);
    mg_server_port ports[1];
    if (mg_get_server_ports(context, 1, ports) < 1) throw std::runtime_error("civetweb has no port");
    port = ports[0].port;
  }
  ~CivetwebServer() {
    mg_stop(context);
    mg_exit_library();
  }
  static int answer(mg_connection* connection, void* self) {
    const std::string& body = static_cast<CivetwebServer*>(self)->body;
    mg_printf(connection,
              "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: %zu\r\nConnection: keep-alive\r\n\r\n",
              body.size());
    mg_write(connection, body.data(), body.size());
    return 200;
  }
};

// One client's round trips, us.
std::vector<double> round_trips(int port, int requests, std::size_t body_size) {
  httplib::Client client("127.0.0.1", port);
  client.set_keep_alive(true);
  client.set_tcp_nodelay(true);  // as a browser does
  std::vector<double> us;
  us.reserve(requests);
  for (int i = 0; i < requests; ++i) {
    const auto start = Clock::now();
    const auto r = client.Get("/state");
    if (!r || r->status != 200 || r->body.size() != body_size) throw std::runtime_error("a request was not answered whole");
    us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
  }
  return us;
}

// Requests answered per second with `clients` at once.
double throughput(int port, int clients, int requests_each, std::size_t body_size) {
  std::atomic<int> failed{0};
  const auto start = Clock::now();
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&] {
      try {
        round_trips(port, requests_each, body_size);
      } catch (const std::exception&) {
        ++failed;
      }
    });
  }
  for (auto& t : threads) t.join();
  if (failed > 0) throw std::runtime_error(std::to_string(failed.load()) + " clients were not answered whole");
  return clients * requests_each / std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  int requests = 5000;
  std::size_t body_kb = 20;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--requests") == 0) requests = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--body-kb") == 0) body_kb = static_cast<std::size_t>(std::atoi(argv[i + 1]));
  }
  const std::string body(body_kb * 1024, 'x');
  try {
    HttplibServer httplib_server(body);
    CivetwebServer civetweb_server(body);
    const std::pair<const char*, int> servers[] = {{"cpp-httplib", httplib_server.port}, {"civetweb", civetweb_server.port}};
    constexpr int kRounds = 3;
    std::vector<double> latency[2], rate[2];
    for (int round = 0; round < kRounds; ++round) {
      for (int s = 0; s < 2; ++s) {
        const auto us = round_trips(servers[s].second, requests, body.size());
        latency[s].insert(latency[s].end(), us.begin(), us.end());
        rate[s].push_back(throughput(servers[s].second, 8, requests / 8, body.size()));
      }
    }
    for (int s = 0; s < 2; ++s) {
      std::cout << servers[s].first << ": one client, " << body_kb << " kB answers: p50 " << percentile(latency[s], 0.5)
                << " us, p99 " << percentile(latency[s], 0.99) << " us (" << latency[s].size()
                << " requests); 8 clients: " << percentile(rate[s], 0.5) << " requests/s (median of " << kRounds
                << " rounds, min " << percentile(rate[s], 0) << ")" << std::endl;
    }
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
