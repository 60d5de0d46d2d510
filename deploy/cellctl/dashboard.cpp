#include "deploy/cellctl/dashboard.hpp"

#include <atomic>
#include <thread>

#include <httplib.h>

#include "deploy/cellctl/dashboard_feed.hpp"
#include "deploy/cellctl/dashboard_routes.hpp"

namespace cellctl {
namespace {

// One server-sent event: `data:` lines may not hold a line break, and JSON text has none.
std::string event(const char* name, const std::string& data) {
  return std::string("event: ") + name + "\ndata: " + data + "\n\n";
}

}  // namespace

struct Dashboard::Impl {
  Impl(const CellConfig& cell, CellObserver& observer) : routes(cell, new_token()), feed(cell, observer) {}

  DashboardRoutes routes;
  DashboardFeed feed;
  std::string host;
  int port = 0;
  httplib::Server server;
  std::atomic<int> followers{0};
  std::atomic<bool> stopping{false};
  std::thread thread;

  void follow(httplib::Response& res) {
    if (++followers > kMaxFollowers) {
      --followers;
      res.status = 503;
      res.set_content("too many pages follow this cell (at most " + std::to_string(kMaxFollowers) + ")\n", "text/plain");
      return;
    }
    res.set_header("Cache-Control", "no-store");
    // The first event holds the state and every bar kept; then each newer state, its new bars.
    auto seen = std::make_shared<std::uint64_t>(0);
    auto bars_seen = std::make_shared<std::uint64_t>(0);
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, seen, bars_seen](std::size_t, httplib::DataSink& sink) {
          if (stopping) return false;
          const DashboardFeed::State state = feed.wait_newer(*seen, std::chrono::seconds(10));
          std::string out;
          for (const auto& [seq, bar] : feed.bars_after(*bars_seen)) {
            out += event("bar", bar);
            *bars_seen = seq;
          }
          if (state.seq > *seen) {
            out += event("state", state.json);
            *seen = state.seq;
          }
          if (out.empty()) out = ": still here\n\n";  // a comment: a dead connection shows at the write
          return !stopping && sink.write(out.data(), out.size());
        },
        [this](bool) { --followers; });
  }
};

Dashboard::Dashboard(const DashboardAddress& address, const CellConfig& cell, CellObserver& observer)
    : impl_(std::make_unique<Impl>(cell, observer)) {
  Impl& d = *impl_;
  d.host = address.host;
  auto& s = d.server;
  s.new_task_queue = [] { return new httplib::ThreadPool(kMaxFollowers + kOtherThreads); };
  s.set_read_timeout(kReadTimeout.count(), 0);
  s.set_write_timeout(kWriteTimeout.count(), 0);
  s.set_keep_alive_max_count(20);
  d.routes.install(s);
  s.Get("/state", [&d](const httplib::Request& req, httplib::Response& res) {
    if (!d.routes.allowed(req, res)) return;
    res.set_header("Cache-Control", "no-store");
    res.set_content(d.feed.wait_newer(0, std::chrono::seconds(2)).json, "application/json");
  });
  s.Get("/events", [&d](const httplib::Request& req, httplib::Response& res) {
    if (d.routes.allowed(req, res)) d.follow(res);
  });
  if (address.port == 0 ? (d.port = s.bind_to_any_port(address.host)) <= 0
                        : !s.bind_to_port(address.host, address.port)) {
    throw std::runtime_error("the dashboard cannot listen on " + address.host + ":" + std::to_string(address.port) +
                             " (taken, or not an address of this host); choose another with --dashboard or `dashboard:`");
  }
  if (address.port != 0) d.port = address.port;
  d.thread = std::thread([&d] { d.server.listen_after_bind(); });
}

Dashboard::~Dashboard() {
  impl_->stopping = true;
  impl_->feed.stop();  // wakes the pages' waits
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

int Dashboard::port() const { return impl_->port; }

const std::string& Dashboard::token() const { return impl_->routes.token(); }

std::string Dashboard::url() const {
  const std::string host = impl_->host == "0.0.0.0" ? "127.0.0.1" : impl_->host;
  return "http://" + host + ":" + std::to_string(impl_->port) + "/?token=" + impl_->routes.token();
}

}  // namespace cellctl
