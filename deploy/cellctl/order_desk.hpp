#pragma once
// The cell's order desk, run by `cellctl up`: orders are rows of the cell's database
// (`cellctl submit` writes one), and the desk keeps a twin running for every order that has
// not ended. A twin that ends before its order did is started again after a second, and
// the new twin takes the order up from the database (services/state). A twin the cell
// stopped (it goes down, cell-sim restarts, a resource restarted under the twin's work)
// records its order INTERRUPTED, and that costs the order nothing; a twin that died (killed,
// crashed) counts, and after `max_deaths` of them the order fails with the reason. So does
// one the cell stopped kMaxAttemptsPerDeath times as often: nothing loops for ever.
// An order's twin is a standby one where one stands by (twin_pool.hpp); the journal's
// "twin started" says its pid. With security each twin has an identity of its own, bound to
// its order (twin_identities.hpp); an order waits while every identity runs a twin.
//
// At most `max_twins` orders are under way at once; the others wait in the cell's queue
// (state QUEUED, journal "queued"), in the order they came, and start as those ahead end. An
// order under way keeps its place while its twin is started again: no queued order takes
// the twin of one that holds a station.
//
// A twin whose heartbeat (services/node/heartbeat.hpp, on the supervisor's socket) stops for
// the cell's `twin_watchdog` is hung: the desk ends it (journal "twin unheard") and, as for
// one that died, starts another for its order.

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/heartbeat_socket.hpp"
#include "deploy/cellctl/processes.hpp"
#include "deploy/cellctl/twin_pool.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {

class OrderDesk {
 public:
  // `participant`: cellctl up's, which binds twins to orders under security; `heartbeats`:
  // the socket the twins beat on (the supervisor's: NOTIFY_SOCKET names it to them).
  OrderDesk(const CellConfig& cell, state::CellStore& store, dds::ParticipantPtr participant, HeartbeatSocket& heartbeats,
            std::function<void(const std::string&)> log, int max_deaths = 5);
  static constexpr int kMaxAttemptsPerDeath = 4;
  ~OrderDesk();

  // Starts twins for the orders that have none, notes the twins that ended. Call often.
  void tend();
  // Stops every twin (each records its order INTERRUPTED); tend() starts them again.
  void interrupt_all();
  std::size_t running() const { return twins_.size(); }
  // The orders waiting in the queue, first to start first.
  static std::vector<std::string> queue(const std::vector<state::OrderRecord>& orders);
  // The order's place in it, 1 next; 0 when it does not wait there.
  static std::size_t place_in(const std::vector<std::string>& queue, const std::string& order);
  // "place 3 of 5", or "" when it does not wait there.
  static std::string place_text(const std::vector<std::string>& queue, const std::string& order);

 private:
  void end_unheard_twins();

  const CellConfig& cell_;
  state::CellStore& store_;
  HeartbeatSocket& heartbeats_;
  std::function<void(const std::string&)> log_;
  int max_deaths_;
  std::map<std::string, int> deaths_;  // order -> its twins that died (since this desk started)
  TwinIdentities identities_;
  std::map<std::string, Twin> twins_;                                        // order -> its twin
  std::map<std::string, std::chrono::steady_clock::time_point> not_before_;  // order -> next start
  TwinPool standby_;
};

}  // namespace cellctl
