#include "deploy/cellctl/order_desk.hpp"

#include <algorithm>
#include <vector>

namespace cellctl {

OrderDesk::OrderDesk(const CellConfig& cell, state::CellStore& store, dds::ParticipantPtr participant,
                     HeartbeatSocket& heartbeats, std::function<void(const std::string&)> log, int max_deaths)
    : cell_(cell),
      store_(store),
      heartbeats_(heartbeats),
      log_(std::move(log)),
      max_deaths_(max_deaths),
      identities_(cell.twin_identities_in_use(), std::move(participant)),
      standby_(twin_standby_argv(cell, executable_dir()), cell.standby_twins, identities_, log_) {}

OrderDesk::~OrderDesk() { interrupt_all(); }

void OrderDesk::end_unheard_twins() {
  const auto stopped = heartbeats_.past_twin_watchdog(cell_.twin_watchdog);
  for (auto& [id, twin] : twins_) {
    const auto beat = stopped.find(twin.process->pid());
    if (beat == stopped.end() || twin.process->poll() >= 0) continue;
    const std::string& why = beat->second;
    log_("the twin of order " + id + " runs but " + why + "; ending it");
    store_.journal("twin-" + id, "unheard", id, why);
    twin.process->stop(std::chrono::seconds(2));  // found ended below, and started again as one that died
  }
}

void OrderDesk::tend() {
  standby_.tend();
  end_unheard_twins();
  const auto now = std::chrono::steady_clock::now();
  std::vector<std::pair<std::string, int>> ended;  // order, its twin's exit code
  for (auto it = twins_.begin(); it != twins_.end();) {
    const int code = it->second.process->poll();
    if (code < 0) {
      ++it;
      continue;
    }
    ended.emplace_back(it->first, code);
    heartbeats_.forget(it->second.process->pid());
    identities_.give_back(it->second.identity);
    it = twins_.erase(it);
  }
  // Read after the twins ended: what each wrote last is in. In the order they came.
  const std::vector<state::OrderRecord> orders = store_.orders();
  const auto record = [&orders](const std::string& id) -> const state::OrderRecord* {
    const auto o = std::find_if(orders.begin(), orders.end(), [&id](const auto& r) { return r.order == id; });
    return o == orders.end() ? nullptr : &*o;
  };

  for (const auto& [id, code] : ended) {
    const state::OrderRecord* o = record(id);
    if (!o || o->ended()) continue;
    // A twin the cell stopped (it went down, cell-sim restarted, a resource restarted under
    // its work) said INTERRUPTED: that is not the twin's failure. One that died says nothing.
    const bool interrupted = o->state == "INTERRUPTED";
    if (!interrupted) ++deaths_[id];
    log_("the twin of order " + id + " ended (exit " + std::to_string(code) + (interrupted ? ", interrupted" : "") +
         ") before its order did; starting it again in 1 s");
    store_.journal("twin-" + id, "ended", id, "exit " + std::to_string(code));
    not_before_[id] = now + std::chrono::seconds(1);
  }

  int under_way = static_cast<int>(std::count_if(orders.begin(), orders.end(), [](const state::OrderRecord& o) {
    return !o.ended() && !o.product.empty() && o.attempts > 0;
  }));
  int place = 0;
  for (const state::OrderRecord& o : orders) {
    const std::string& id = o.order;
    if (o.ended() || twins_.count(id) || o.product.empty()) continue;  // no product: not the desk's order
    // Cancelled before a twin took it: nothing of the cell is its yet, so the desk ends it. A
    // twin that took it fails it itself, through the cleanup of any failure.
    if (!o.cancelled_by.empty() && o.attempts == 0) {
      const std::string why = "cancelled by " + o.cancelled_by + " before it started";
      store_.set_order(id, "FAILED", why, 1, {"cellctl", "cancelled", why});
      log_("order " + id + " " + why);
      continue;
    }
    if (o.attempts == 0 && under_way >= cell_.max_twins) {
      ++place;
      if (o.state != "QUEUED") {
        store_.set_order(id, "QUEUED", "", -1,
                         {"cellctl", "queued",
                          "place " + std::to_string(place) + ", behind " + std::to_string(under_way) +
                             " orders under way (max_twins " + std::to_string(cell_.max_twins) + ")"});
      }
      continue;
    }
    if (const auto wait = not_before_.find(id); wait != not_before_.end() && now < wait->second) continue;
    std::string why;
    if (deaths_[id] >= max_deaths_) {
      why = "its twin died " + std::to_string(deaths_[id]) + " times before the order ended";
    } else if (o.attempts >= kMaxAttemptsPerDeath * max_deaths_) {
      why = "its twin was started " + std::to_string(o.attempts) + " times, and the cell stopped it every time";
    }
    if (!why.empty()) {
      if (!o.reason.empty()) why += "; last: " + o.reason;
      // What to do next (the twins wrote to cellctl up's output, which the cell's operator has).
      why += ". The twins' output is in the cell's log (cellctl up); once the cause is fixed, submit the order again "
             "under another id";
      store_.set_order(id, "FAILED", why, 1, {"cellctl", "FAILED", why});
      log_("order " + id + " failed: " + why);
      continue;
    }
    // Every identity runs a twin: the order waits for one to end (uncounted).
    if (standby_.standing_by() == 0 && !identities_.any_free()) continue;
    try {
      const int attempt = store_.count_attempt(id);
      // Until the twin says more: one killed before it wrote a word counts as died.
      store_.set_order(id, "SUBMITTED", o.reason);
      const auto order_args = twin_order_args(cell_, id, o.product, o.out, o.sequence, o.path, cell_.state_folder(), 30, o.quote);
      Twin twin = standby_.take("twin-" + id, id, order_args);
      const bool was_standing_by = twin.process != nullptr;
      if (!twin.process) {
        twin = identities_.start(id, twin_argv(cell_, executable_dir(), id, o.product, o.out, o.sequence, o.path,
                                               cell_.state_folder(), 30, o.quote));
        if (!twin.process) continue;
      }
      // The pid says which process is the order's twin (a standby one has no --order to see).
      const std::string started = "attempt " + std::to_string(attempt) + ", pid " + std::to_string(twin.process->pid()) +
                                  (was_standing_by ? ", standing by" : "") +
                                  (twin.identity.empty() ? "" : ", identity " + twin.identity);
      heartbeats_.watch(twin.process->pid());
      twins_[id] = std::move(twin);  // before anything else can throw: its identity comes back when it ends
      if (attempt == 1) ++under_way;
      store_.journal("cellctl", "twin started", id, started);
      if (attempt > 1) log_("order " + id + ": twin started again (attempt " + std::to_string(attempt) + ")");
    } catch (const std::exception& e) {
      store_.set_order(id, "FAILED", std::string("its twin cannot be started: ") + e.what(), 1);
    }
  }
}

std::vector<std::string> OrderDesk::queue(const std::vector<state::OrderRecord>& orders) {
  std::vector<std::string> out;
  for (const auto& o : orders) {
    if (o.state == "QUEUED") out.push_back(o.order);
  }
  return out;
}

std::size_t OrderDesk::place_in(const std::vector<std::string>& queue, const std::string& order) {
  const auto q = std::find(queue.begin(), queue.end(), order);
  return q == queue.end() ? 0 : static_cast<std::size_t>(q - queue.begin()) + 1;
}

std::string OrderDesk::place_text(const std::vector<std::string>& queue, const std::string& order) {
  const std::size_t place = place_in(queue, order);
  return place == 0 ? "" : "place " + std::to_string(place) + " of " + std::to_string(queue.size());
}

void OrderDesk::interrupt_all() {
  std::vector<Process*> all;
  for (auto& [id, twin] : twins_) all.push_back(twin.process.get());
  stop_all(all);
  for (auto& [id, twin] : twins_) {
    heartbeats_.forget(twin.process->pid());
    identities_.give_back(twin.identity);
  }
  twins_.clear();
}

}  // namespace cellctl
