#include "deploy/cellctl/dashboard_routes.hpp"

#include <openssl/crypto.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "deploy/cellctl/dashboard_assets.hpp"
#include "deploy/cellctl/order_intake.hpp"
#include "deploy/cellctl/resource_service.hpp"
#include "services/state/cell_store.hpp"
#include "twin/report/viewer/viewer_assets.hpp"

namespace cellctl {
namespace {

constexpr const char* kCookie = "cell_token";

bool same(const std::string& a, const std::string& b) {
  return a.size() == b.size() && CRYPTO_memcmp(a.data(), b.data(), a.size()) == 0;
}

// The token a request carries: `Authorization: Bearer T` or the cookie.
std::string token_of(const httplib::Request& req) {
  const std::string auth = req.get_header_value("Authorization");
  if (auth.rfind("Bearer ", 0) == 0) return auth.substr(7);
  const std::string cookies = req.get_header_value("Cookie");
  const std::string key = std::string(kCookie) + "=";
  for (std::size_t at = cookies.find(key); at != std::string::npos; at = cookies.find(key, at + 1)) {
    if (at == 0 || cookies[at - 1] == ' ' || cookies[at - 1] == ';') {
      const std::size_t end = cookies.find(';', at);
      return cookies.substr(at + key.size(), end == std::string::npos ? std::string::npos : end - at - key.size());
    }
  }
  return "";
}

}  // namespace

std::string new_token() { return random_hex(24); }

std::string DashboardRoutes::operator_of(const httplib::Request& req) const {
  if (!req.ssl || SSL_get_verify_result(req.ssl) != X509_V_OK) return "";
  X509* peer = SSL_get0_peer_certificate(req.ssl);
  if (!peer) return "";
  char name[256] = {};
  if (X509_NAME_get_text_by_NID(X509_get_subject_name(peer), NID_commonName, name, sizeof name) <= 0) return "";
  for (const auto& o : cell_.operators) {
    if (o == name) return o;
  }
  return "";
}

std::string DashboardRoutes::who(const httplib::Request& req) const {
  const std::string name = operator_of(req);
  return name.empty() ? "the operator (dashboard)" : "operator " + name + " (dashboard)";
}

bool DashboardRoutes::allowed(const httplib::Request& req, httplib::Response& res) const {
  if (same(token_of(req), token_) || !operator_of(req).empty()) return true;
  res.status = 401;
  res.set_content("This cell's dashboard needs the operator token that cellctl up printed: open the address it gave, "
                  "with ?token=..." +
                      std::string(cell_.security_dir.empty() ? ""
                                                             : "; or a certificate of the cell's CA of one of its operators "
                                                               "(the deployment file's operators:, `cellctl pki issue`)") +
                      "\n",
                  "text/plain");
  return false;
}

void DashboardRoutes::serve_page(const httplib::Request& req, httplib::Response& res) const {
  if (req.has_param("token")) {
    if (!same(req.get_param_value("token"), token_)) {
      res.status = 401;
      res.set_content("wrong token\n", "text/plain");
      return;
    }
    // Out of the address bar and the history: the cookie carries it from now on.
    res.set_header("Set-Cookie", std::string(kCookie) + "=" + token_ + "; Path=/; HttpOnly; SameSite=Strict");
    res.set_redirect("/");
    return;
  }
  if (!allowed(req, res)) return;
  res.set_content(std::string(dashboard::page_html()), "text/html; charset=utf-8");
}

// An order's report, plan or animation, from the folder its twin wrote them to.
void DashboardRoutes::serve_result(const std::string& order, const std::string& file, httplib::Response& res) const {
  std::string out;
  for (const auto& o : state::CellStore(cell_.state_folder()).orders()) {
    if (o.order == order) out = o.out;
  }
  const std::filesystem::path path = std::filesystem::path(out) / file;
  std::error_code error;
  const auto size = out.empty() ? 0 : std::filesystem::file_size(path, error);
  if (out.empty() || error) {
    res.status = 404;
    res.set_content("order " + order + " has no " + file + (out.empty() ? " (no such order)" : " (yet)") + "\n",
                    "text/plain");
    return;
  }
  if (size > kMaxResultBytes) {
    res.status = 413;
    res.set_content(file + " of order " + order + " is larger than the dashboard serves: read it from " + path.string() + "\n",
                    "text/plain");
    return;
  }
  std::ifstream in(path, std::ios::binary);
  std::string bytes(size, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (file == "report.html") {
    // The report runs its own inline viewer, sandboxed: an origin of its own, no access to
    // the dashboard's. Its policy replaces the page's (two would both apply).
    res.headers.erase("Content-Security-Policy");
    res.set_header("Content-Security-Policy",
                   "sandbox allow-scripts; default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
                   "img-src data: blob:; connect-src data: blob:");
    res.set_content(std::move(bytes), "text/html; charset=utf-8");
  } else {
    res.set_header("Content-Disposition", "attachment; filename=\"" + order + "-" + file + "\"");
    res.set_content(std::move(bytes), file == "plan.json" ? "application/json" : "model/gltf+json");
  }
}

// Before a request's body is read: only an upload of the operator's has one larger than a
// form's, and it needs the token first.
httplib::Server::HandlerResponse DashboardRoutes::before_body(const httplib::Request& req, httplib::Response& res) const {
  using Handled = httplib::Server::HandlerResponse;
  const bool upload = req.method == "POST" && req.path == "/orders";
  const auto length = req.get_header_value<std::uint64_t>("Content-Length");
  if (!upload && (length > kMaxFormBytes || req.has_header("Transfer-Encoding"))) {
    res.status = 413;
    res.set_header("Connection", "close");
    res.set_content("this request's body is larger than the dashboard takes\n", "text/plain");
    return Handled::Handled;
  }
  if (req.method != "POST") return Handled::Unhandled;
  if (!allowed(req, res)) return Handled::Handled;
  // A page of another site may post here with the operator's cookie no more than read (the
  // cookie is SameSite=Strict); a browser names the page's origin, and it must be this one.
  const std::string origin = req.get_header_value("Origin");
  if (!origin.empty() && origin != (req.ssl ? "https://" : "http://") + req.get_header_value("Host")) {
    res.status = 403;
    res.set_content("an action on this cell comes from its own dashboard only\n", "text/plain");
    return Handled::Handled;
  }
  return Handled::Unhandled;
}

// POST /orders[?order=ID], the body a product's zip: an order, as `cellctl submit` makes one.
void DashboardRoutes::take_upload(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& content) {
  struct Counted {  // this upload among those under way, until it is answered (or throws)
    std::atomic<int>& n;
    ~Counted() { --n; }
  } counted{uploads_};
  if (++uploads_ > kMaxUploads) {
    res.status = 503;
    res.set_content(std::to_string(kMaxUploads) + " uploads are under way; send this one when they are done\n", "text/plain");
    return;
  }
  std::string zip;
  const auto limit = max_upload_bytes();
  UploadAnswer answer{413, "", "the upload is larger than the desk takes (desk: max_order_mb)"};
  if (req.get_header_value<std::uint64_t>("Content-Length") <= limit) {
    bool over = false;
    const bool whole = content([&](const char* data, std::size_t n) {
      over = zip.size() + n > limit;
      if (!over) zip.append(data, n);
      return !over;
    });
    if (!whole && !over) {
      answer = {400, "", "the upload did not arrive whole"};
    } else if (whole) {
      state::CellStore store(cell_.state_folder());
      answer = cellctl::take_upload(cell_, store, zip, req.get_param_value("order"), "dashboard");
    }
  }
  res.status = answer.status;
  res.set_content(nlohmann::json{{"order", answer.order}, {"message", answer.message}}.dump(), "application/json");
}

std::size_t DashboardRoutes::max_upload_bytes() const {
  return static_cast<std::size_t>(cell_.desk.max_order_mb * 1e6) + (1u << 20);  // a zip's own bytes over its files'
}

void DashboardRoutes::install(httplib::Server& s) {
  s.set_payload_max_length(max_upload_bytes());  // other requests: kMaxFormBytes (before_body)
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) { return before_body(req, res); });
  s.set_default_headers({{"Content-Security-Policy",
                          "default-src 'none'; script-src 'self'; style-src 'self'; connect-src 'self'; "
                          "img-src 'self' data:; frame-ancestors 'none'; base-uri 'none'; form-action 'self'"},
                         {"X-Content-Type-Options", "nosniff"},
                         {"Referrer-Policy", "no-referrer"}});
  s.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
    res.status = 500;
    res.set_content("the dashboard could not answer this request\n", "text/plain");
  });
  s.Get("/", [this](const httplib::Request& req, httplib::Response& res) { serve_page(req, res); });
  // The page's own script and style: no cell data in them, served to anyone (the policy
  // allows scripts from here only).
  s.Get("/dashboard.js", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(dashboard::script_js()), "text/javascript; charset=utf-8");
  });
  s.Get("/three.js", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(twin::viewer::three_js()), "text/javascript; charset=utf-8");
  });
  s.Get("/dashboard.css", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(dashboard::style_css()), "text/css; charset=utf-8");
  });
  s.Get(R"(/orders/([A-Za-z0-9_.-]{1,128})/(report\.html|plan\.json|animation\.gltf))",
        [this](const httplib::Request& req, httplib::Response& res) {
          if (allowed(req, res)) serve_result(req.matches[1], req.matches[2], res);
        });
  s.Post(R"(/orders/([A-Za-z0-9_.-]{1,128})/cancel)", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string order = req.matches[1];
    state::CellStore store(cell_.state_folder());
    const ActionAnswer answer = cancel_order(store, order, who(req));
    res.status = answer.status;
    res.set_content(nlohmann::json{{"order", order}, {"message", answer.message}}.dump(), "application/json");
  });
  // Out of service, the body saying why (plain text), and back.
  s.Post(R"(/resources/([A-Za-z0-9_.-]{1,128})/(out-of-service|in-service))",
         [this](const httplib::Request& req, httplib::Response& res) {
           const std::string resource = req.matches[1];
           const bool out = req.matches[2] == "out-of-service";
           ActionAnswer answer{400, "say why it goes out of service (the request's body)"};
           if (!out || !req.body.empty()) {
             state::CellStore store(cell_.state_folder());
             answer = set_resource_service(cell_, store, resource, out ? req.body : "", who(req));
           }
           res.status = answer.status;
           res.set_content(nlohmann::json{{"resource", resource}, {"message", answer.message}}.dump(), "application/json");
         });
  s.Post("/orders", [this](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& content) {
    take_upload(req, res, content);
  });
}

}  // namespace cellctl
