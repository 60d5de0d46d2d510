#include "deploy/cellctl/dashboard_feed.hpp"

#include <filesystem>
#include <iostream>
#include <set>

#include "deploy/cellctl/cell_status.hpp"
#include "services/dds/conversions.hpp"
#include "services/dds/endpoints.hpp"
#include "simulationPubSubTypes.h"

namespace cellctl {
namespace {

using nlohmann::json;

double unix_seconds(std::chrono::system_clock::time_point t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count();
}

// The journal's events an operator must see: a process that ended, hung or restarted, the
// whole cell restarted, parts held for inspection, an order that failed or left its plan, a
// resource taken out of service or back.
bool is_alarm(const state::JournalEntry& e) {
  static const std::set<std::string> alarms{"ended",       "unheard",  "restarting all", "inspection",
                                            "FAILED",      "aborted",  "plan not followed", "unexpected on_station",
                                            "INTERRUPTED", "returned", "out of service", "in service"};
  return alarms.count(e.event) > 0 || (e.event == "restarted" && e.source != "cellctl");
}

}  // namespace

struct DashboardFeed::SceneReaders {
  dds::Reader<cell::SimRequest, cell::SimRequestPubSubType> requests;
  dds::Reader<cell::SimReply, cell::SimReplyPubSubType> replies;
};

DashboardFeed::DashboardFeed(const CellConfig& cell, CellObserver& observer)
    : cell_(cell),
      observer_(observer),
      scene_([&cell] {
        const auto ids = cell.resource_ids();
        return std::set<std::string>(ids.begin(), ids.end());
      }()),
      thread_([this] { run(); }) {
  // Twins' virtual assemblies make most of these: they are read and left (PhysicalScene).
  scene_readers_.reset(new SceneReaders{
      {observer.participant(), "cell/sim/requests", dds::TopicKind::events,
       [this](const cell::SimRequest& r) {
         if (scene_.take(r, observer_.sim_now())) observer_.note_change();
       }},
      {observer.participant(), "cell/sim/replies", dds::TopicKind::events, [this](const cell::SimReply& r) {
         if (scene_.take(r)) observer_.note_change();
       }}});
}

DashboardFeed::~DashboardFeed() { stop(); }

void DashboardFeed::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  newer_.notify_all();
  if (thread_.joinable()) thread_.join();
}

DashboardFeed::State DashboardFeed::wait_newer(std::uint64_t seen, std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  newer_.wait_for(lock, timeout, [&] { return stopping_ || state_.seq > seen; });
  return state_;
}

std::vector<std::pair<std::uint64_t, std::string>> DashboardFeed::bars_after(std::uint64_t after) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::pair<std::uint64_t, std::string>> out;
  for (const auto& bar : bars_) {
    if (bar.first > after) out.push_back(bar);
  }
  return out;
}

void DashboardFeed::run() {
  std::uint64_t heard = 0;
  auto last_build = std::chrono::steady_clock::time_point{};
  for (;;) {
    heard = observer_.wait_for_change(heard, kRefresh);
    {
      std::unique_lock<std::mutex> lock(mutex_);
      // Changes that come during the gap are taken by the next build, all at once.
      newer_.wait_until(lock, last_build + kMinGap, [&] { return stopping_; });
      if (stopping_) return;
    }
    last_build = std::chrono::steady_clock::now();
    try {
      build();
    } catch (const std::exception& e) {
      // The page shows the cell as last built; the cell goes on (a database busy a moment).
      std::cerr << "cellctl up: dashboard: " << e.what() << std::endl;
    } catch (...) {
      std::cerr << "cellctl up: dashboard: an unknown error building its state" << std::endl;
    }
  }
}

void DashboardFeed::take_command_events(json& new_alarms) {
  const auto events = observer_.command_events_after(events_seen_);
  if (events.empty()) return;
  events_seen_ = events.back().seq;
  std::vector<std::pair<std::string, double>> ended;  // bar, its end
  for (const CommandHeard& e : events) {
    if (e.state == cell::ABORTED || e.state == cell::REJECTED) {
      new_alarms.push_back({{"time", unix_seconds(e.heard_at)},
                            {"source", e.resource},
                            {"event", e.state == cell::REJECTED ? "refused" : "aborted"},
                            {"order", e.order},
                            {"detail", e.operation + (e.part.empty() ? "" : " " + e.part) + ": " + e.reason}});
    }
    if (const auto bar = commands_.take(e)) {
      ended.emplace_back(json{{"resource", bar->resource},
                              {"order", bar->order},
                              {"operation", bar->operation},
                              {"part", bar->part},
                              {"start", bar->start},
                              {"end", bar->end},
                              {"state", dds::state_name(bar->state)}}
                             .dump(),
                         bar->end);
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [bar, end] : ended) {
    bars_.emplace_back(++bar_seq_, std::move(bar));
    bar_ends_.push_back(end);
  }
  const double now = observer_.sim_now();
  while (!bars_.empty() && (bars_.size() > kKeptBars || bar_ends_.front() < now - kBarsWindow)) {
    bars_.pop_front();
    bar_ends_.pop_front();
  }
}

void DashboardFeed::take_journal(json& new_alarms) {
  if (!store_) {
    if (!std::filesystem::exists(state::CellStore::file_in(cell_.state_folder()))) return;
    store_ = std::make_unique<state::CellStore>(cell_.state_folder());
  }
  for (const auto& e : store_->journal_since(journal_seen_)) {
    journal_seen_ = e.seq;
    if (e.event == "restarted") restarted_at_[e.source] = e.time;
    const bool all = e.event == "restarting all";
    if (e.event == "ended" || all) {
      for (const auto& id : cell_.resource_ids()) {
        if (all || process_of(cell_, id) == e.source) ended_at_[process_of(cell_, id)] = e.time;
      }
      commands_.lose([&](const std::string& resource) { return all || process_of(cell_, resource) == e.source; });
    }
    if (!is_alarm(e)) continue;
    new_alarms.push_back({{"time", e.time}, {"source", e.source}, {"event", e.event}, {"order", e.order}, {"detail", e.detail}});
  }
}

// What the operator should look at first, worst first: a resource gone, a part type whose
// count does not add up, an order that failed, a resource that refuses commands.
json DashboardFeed::attention(const json& status) const {
  json out = json::array();
  for (const auto& r : status["resources"]) {
    if (!r["alive"].get<bool>()) out.push_back({{"severity", "alarm"}, {"what", r["id"].get<std::string>() + " is gone"}});
  }
  for (const auto& r : status["resources"]) {
    if (!r.value("out_of_service", std::string()).empty()) {
      out.push_back({{"severity", "warning"},
                     {"what", r["id"].get<std::string>() + " is out of service: " + r["out_of_service"].get<std::string>()}});
    }
  }
  for (const auto& [type, c] : status["inventory"].items()) {
    if (!c["conserved"].get<bool>()) {
      out.push_back({{"severity", "alarm"}, {"what", type + ": the parts do not add up to the stock the cell began with"}});
    }
  }
  for (const auto& o : status["orders"]) {
    if (o["state"] == "FAILED") {
      out.push_back({{"severity", "warning"},
                     {"what", o["order"].get<std::string>() + " failed: " + o["reason"].get<std::string>()}});
    }
  }
  for (const auto& r : status["resources"]) {
    if (r.value("refused", 0) > 0) {
      out.push_back({{"severity", "notice"},
                     {"what", r["id"].get<std::string>() + " refused " + std::to_string(r["refused"].get<long>()) +
                                  " command(s), last: " + r.value("last_refusal", std::string())}});
    }
  }
  return out;
}

void DashboardFeed::build() {
  json new_alarms = json::array();
  take_command_events(new_alarms);
  take_journal(new_alarms);
  for (auto& a : new_alarms) alarms_.push_front(std::move(a));
  while (alarms_.size() > kKeptAlarms) alarms_.pop_back();

  json status = cell_status(cell_, observer_, store_.get());
  const auto under_way = commands_.under_way();
  const auto heard = observer_.resources();
  for (auto& r : status["resources"]) {
    const std::string id = r["id"];
    if (const auto restarted = restarted_at_.find(process_of(cell_, id)); restarted != restarted_at_.end()) {
      r["restarted_at"] = restarted->second;
    }
    const auto ended = ended_at_.find(process_of(cell_, id));
    const auto view = heard.find(id);
    if (ended != ended_at_.end() && view != heard.end() && unix_seconds(view->second.heard_at) < ended->second) {
      r["alive"] = false;  // its process ended, and the new one is not heard yet
    }
    const auto it = under_way.find(id);
    if (it == under_way.end()) continue;
    r["current"] = {{"operation", it->second.operation},
                    {"order", it->second.order},
                    {"part", it->second.part},
                    {"since", it->second.since}};
  }
  status.erase("state_dir");
  status["attention"] = attention(status);
  status["alarms"] = json::array();
  for (const json& a : alarms_) status["alarms"].push_back(a);
  status["bars"] = bar_seq_;
  status["domain"] = cell_.domain;
  status["real_time_factor"] = cell_.real_time_factor;
  status["bodies"] = scene_.bodies(observer_.sim_now());

  std::string content = status.dump();
  if (content == last_content_) return;
  last_content_ = std::move(content);
  // When the page shows it, it knows how old the change is (docs/performance.md).
  status["heard_at"] = unix_seconds(observer_.changed_at());
  status["built_at"] = unix_seconds(std::chrono::system_clock::now());
  status["sim_time"] = observer_.sim_now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_.seq += 1;
    status["seq"] = state_.seq;
    state_.json = status.dump();
  }
  newer_.notify_all();
}

}  // namespace cellctl
