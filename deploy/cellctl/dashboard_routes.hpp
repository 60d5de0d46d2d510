#pragma once
// What the cell's dashboard answers besides the live feed (dashboard.hpp): the gate every
// request passes (the operator's token; no body past a form's but an upload's, whose token is
// asked before it is read; an action from the dashboard's own origin only), the page and its
// assets, an order's report, plan and animation, and the operator's uploads that become
// orders (order_intake.hpp). Apart from the server and the feed so that a fuzz target can
// send it any request (tests/fuzz/fuzz_dashboard_requests.cpp).

#include <atomic>
#include <cstdint>
#include <string>

#include "deploy/cellctl/cell_config.hpp"

// After Eigen (through cell_config.hpp): httplib brings <resolv.h>, whose `_res` macro breaks
// Eigen's headers.
#include <httplib.h>

namespace cellctl {

// 48 hex digits from 24 random bytes.
std::string new_token();

class DashboardRoutes {
 public:
  static constexpr std::uintmax_t kMaxResultBytes = 256u << 20;  // an order's report, plan or animation
  static constexpr std::uint64_t kMaxFormBytes = 64 * 1024;       // any request's body but an upload's
  static constexpr int kMaxUploads = 2;                           // products being uploaded at once

  DashboardRoutes(const CellConfig& cell, std::string token) : cell_(cell), token_(std::move(token)) {}
  // The server's limits, headers and gate, and every route of this class.
  void install(httplib::Server& server);
  // Whether the request carries the token, or came (over TLS, with security) with a
  // certificate of the cell's CA of one of the file's `operators:`; if not, `res` says what
  // is missing.
  bool allowed(const httplib::Request& req, httplib::Response& res) const;
  const std::string& token() const { return token_; }

 private:
  std::string operator_of(const httplib::Request& req) const;  // "" when no operator's certificate
  std::string who(const httplib::Request& req) const;          // who acts, for the journal
  httplib::Server::HandlerResponse before_body(const httplib::Request& req, httplib::Response& res) const;
  void serve_page(const httplib::Request& req, httplib::Response& res) const;
  void serve_result(const std::string& order, const std::string& file, httplib::Response& res) const;
  void take_upload(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& content);
  std::size_t max_upload_bytes() const;

  const CellConfig& cell_;
  const std::string token_;
  std::atomic<int> uploads_{0};
};

}  // namespace cellctl
