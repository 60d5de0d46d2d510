#include "deploy/cellctl/dashboard.hpp"

#include <atomic>
#include <csignal>
#include <filesystem>
#include <thread>

#include <httplib.h>
#include <openssl/ssl.h>

#include "deploy/cellctl/dashboard_feed.hpp"
#include "deploy/cellctl/dashboard_routes.hpp"
#include "services/dds/security.hpp"

namespace cellctl {
namespace {

// One server-sent event: `data:` lines may not hold a line break, and JSON text has none.
std::string event(const char* name, const std::string& data) {
  return std::string("event: ") + name + "\ndata: " + data + "\n\n";
}

// With security: HTTPS with the cell's "dashboard" identity, asking each browser for a
// certificate of the cell's CA (an operator's lets it in without the token; one the CA did
// not sign ends the handshake; none leaves the token to decide).
std::unique_ptr<httplib::Server> make_server(const CellConfig& cell) {
  if (cell.security_dir.empty()) return std::make_unique<httplib::Server>();
  const dds::IdentityFiles files = dds::identity_files(cell.security_dir, "dashboard");
  for (const auto& f : {files.cert, files.key, files.ca_cert}) {
    if (!std::filesystem::exists(f)) {
      throw std::runtime_error("the dashboard of a secure cell serves HTTPS with the identity 'dashboard', and " + f.string() +
                               " is missing: `cellctl pki issue " + cell.security_dir.string() + " dashboard`");
    }
  }
  auto server = std::make_unique<httplib::SSLServer>([&files](SSL_CTX& ctx) {
    if (SSL_CTX_use_certificate_chain_file(&ctx, files.cert.c_str()) != 1 ||
        SSL_CTX_use_PrivateKey_file(&ctx, files.key.c_str(), SSL_FILETYPE_PEM) != 1 || SSL_CTX_check_private_key(&ctx) != 1 ||
        SSL_CTX_load_verify_locations(&ctx, files.ca_cert.c_str(), nullptr) != 1) {
      return false;
    }
    SSL_CTX_set_client_CA_list(&ctx, SSL_load_client_CA_file(files.ca_cert.c_str()));
    SSL_CTX_set_verify(&ctx, SSL_VERIFY_PEER, nullptr);
    return true;
  });
  if (!server->is_valid()) {
    throw std::runtime_error("the dashboard cannot use its TLS identity " + files.cert.parent_path().string() +
                             " (a certificate and key of the cell's CA: `cellctl pki issue " + cell.security_dir.string() +
                             " dashboard`)");
  }
  return server;
}

}  // namespace

struct Dashboard::Impl {
  Impl(const CellConfig& cell, CellObserver& observer)
      : routes(cell, new_token()), server(make_server(cell)), feed(cell, observer) {}

  DashboardRoutes routes;
  std::unique_ptr<httplib::Server> server;
  DashboardFeed feed;
  std::string host;
  int port = 0;
  bool tls = false;
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
  // cpp-httplib (Debian's build) sends without MSG_NOSIGNAL, and OpenSSL writes with write():
  // a write to a browser that left ends the process by SIGPIPE unless it is ignored. The
  // library checks a connection before it writes, and the tests' pages that leave did not
  // draw one; ignored, one that slips through is an EPIPE that drops that page alone.
  std::signal(SIGPIPE, SIG_IGN);
  Impl& d = *impl_;
  d.host = address.host;
  d.tls = !cell.security_dir.empty();
  auto& s = *d.server;
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
  d.thread = std::thread([&d] { d.server->listen_after_bind(); });
}

Dashboard::~Dashboard() {
  impl_->stopping = true;
  impl_->feed.stop();  // wakes the pages' waits
  impl_->server->stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

int Dashboard::port() const { return impl_->port; }

const std::string& Dashboard::token() const { return impl_->routes.token(); }

std::string Dashboard::url() const {
  const std::string host = impl_->host == "0.0.0.0" ? "127.0.0.1" : impl_->host;
  return std::string(impl_->tls ? "https://" : "http://") + host + ":" + std::to_string(impl_->port) +
         "/?token=" + impl_->routes.token();
}

}  // namespace cellctl
