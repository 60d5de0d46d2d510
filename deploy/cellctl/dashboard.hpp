#pragma once
// The cell's live dashboard, served by `cellctl up --dashboard [ADDR:]PORT` (or the
// deployment file's `dashboard:`): one page (deploy/cellctl/dashboard/), with every asset
// built in, that shows the running cell as DashboardFeed builds it, pushed to the browser by
// server-sent events as it changes (docs/dashboard.md), and each order's report, plan and
// animation (`/orders/ID/report.html`, `plan.json`, `animation.gltf`).
//
// Only an operator with the token `cellctl up` prints (and writes to the state folder, 0600)
// sees it: `/?token=T` sets a cookie (HttpOnly, SameSite=Strict) and every other request
// needs that cookie or `Authorization: Bearer T`. The page's policy (CSP) lets it run its own
// scripts and nothing else, and it writes every text of the cell's as text, never as markup.
// At most kMaxFollowers pages follow the cell at once, each on a thread of its own; a slow one
// is dropped after kWriteTimeout. kOtherThreads more answer everything else, and a connection
// that does not finish its request holds one at most kReadTimeout: a crowd of stalled
// connections delays the page by a few seconds, and no page can slow the feed or the cell.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/cell_observer.hpp"

namespace cellctl {

class Dashboard {
 public:
  static constexpr int kMaxFollowers = 8;
  static constexpr int kOtherThreads = 24;
  static constexpr std::chrono::seconds kWriteTimeout{5};
  static constexpr std::chrono::seconds kReadTimeout{2};

  // Listens at once; throws with the reason when it cannot (the port is taken).
  Dashboard(const DashboardAddress& address, const CellConfig& cell, CellObserver& observer);
  ~Dashboard();
  Dashboard(const Dashboard&) = delete;
  Dashboard& operator=(const Dashboard&) = delete;

  int port() const;
  const std::string& token() const;
  std::string url() const;  // with the token: what the operator opens

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cellctl
