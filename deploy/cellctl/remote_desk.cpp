#include "deploy/cellctl/remote_desk.hpp"

#include <algorithm>
#include <fstream>
#include <optional>

#include "deploy/cellctl/order_desk.hpp"
#include "deploy/cellctl/order_intake.hpp"

namespace cellctl {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kUploadsPerClient = 4;  // submissions whose files arrive at once

std::string text_of(cell::DeskState s) {
  switch (s) {
    case cell::DESK_ACCEPTED: return "accepted";
    case cell::DESK_REFUSED: return "refused";
    case cell::DESK_PROGRESS: return "progress";
    case cell::DESK_DONE: return "done";
    case cell::DESK_FAILED: return "failed";
  }
  return "?";
}

}  // namespace

struct RemoteDesk::Client {
  std::string id;
  std::mutex mutex;  // guards uploads and requests (DDS threads add, tend() takes)
  std::map<std::string, FileAssembly> uploads;
  std::map<std::string, std::string> upload_errors;  // submission -> why its files were refused
  std::deque<std::string> upload_order;              // oldest first
  std::deque<cell::OrderRequest> requests;
  std::deque<std::chrono::steady_clock::time_point> requested_at;  // the last minute's orders
  std::unique_ptr<dds::Reader<cell::FileChunk, cell::FileChunkPubSubType>> files;
  std::unique_ptr<dds::Reader<cell::OrderRequest, cell::OrderRequestPubSubType>> orders;
  std::unique_ptr<dds::Writer<cell::DeskReply, cell::DeskReplyPubSubType>> replies;
  std::unique_ptr<ChunkWriter> results;

  void take_chunk(const cell::FileChunk& chunk, std::uint64_t max_bytes) {
    const std::string submission = chunk.submission().to_string();
    std::lock_guard<std::mutex> lock(mutex);
    if (upload_errors.count(submission)) return;
    auto it = uploads.find(submission);
    if (it == uploads.end()) {
      if (!good_order_id(submission)) return;  // answered when its order comes
      while (upload_order.size() >= kUploadsPerClient) {  // an upload never finished: the oldest goes
        uploads.erase(upload_order.front());
        upload_order.pop_front();
      }
      it = uploads.emplace(submission, FileAssembly(max_bytes)).first;
      upload_order.push_back(submission);
    }
    std::string why;
    try {
      why = it->second.add(chunk);
    } catch (const std::exception& e) {  // no memory for the file: on a DDS thread, nothing may escape
      why = std::string("the desk could not keep the files: ") + e.what();
    }
    if (!why.empty()) {
      if (upload_errors.size() >= kUploadsPerClient) upload_errors.erase(upload_errors.begin());
      upload_errors[submission] = why;
      uploads.erase(it);
      upload_order.erase(std::find(upload_order.begin(), upload_order.end(), submission));
    }
  }
};

RemoteDesk::RemoteDesk(const CellConfig& cell, state::CellStore& store, CellObserver& observer,
                       std::function<void(const std::string&)> log)
    : cell_(cell), store_(store), observer_(observer), log_(std::move(log)) {
  const auto max_bytes = static_cast<std::uint64_t>(cell.desk.max_order_mb * 1e6);
  const dds::ParticipantPtr& participant = observer.participant();
  for (const auto& id : cell.clients) {
    auto client = std::make_unique<Client>();
    Client* c = client.get();
    c->id = id;
    c->replies = std::make_unique<dds::Writer<cell::DeskReply, cell::DeskReplyPubSubType>>(
        participant, desk_topic("replies", id), dds::TopicKind::state);
    c->results = std::make_unique<ChunkWriter>(participant, desk_topic("results", id), dds::TopicKind::events, chunk_qos());
    c->files = std::make_unique<dds::Reader<cell::FileChunk, cell::FileChunkPubSubType>>(
        participant, desk_topic("files", id), dds::TopicKind::events,
        [c, max_bytes](const cell::FileChunk& chunk) { c->take_chunk(chunk, max_bytes); },
        std::function<void(const cell::FileChunk&)>{}, chunk_qos());
    c->orders = std::make_unique<dds::Reader<cell::OrderRequest, cell::OrderRequestPubSubType>>(
        participant, desk_topic("orders", id), dds::TopicKind::events, [c](const cell::OrderRequest& r) {
          std::lock_guard<std::mutex> lock(c->mutex);
          if (c->requests.size() < 64) c->requests.push_back(r);  // more waiting is a flood: dropped
        });
    clients_[id] = std::move(client);
  }
  // Orders of clients that a desk before this one took: followed to their end again.
  for (const auto& known : store.orders()) {
    const fs::path out(known.out);
    const fs::path folder = out.parent_path();
    if (known.ended() || out.filename() != "out" || folder.parent_path().parent_path() != cell.state_folder() / "desk") continue;
    const std::string client = folder.parent_path().filename(), submission = folder.filename();
    if (clients_.count(client)) accepted_.push_back({client, submission, known.request, known.order, ""});
  }
}

RemoteDesk::~RemoteDesk() = default;

void RemoteDesk::reply(Client& client, const std::string& submission, const std::string& request, const std::string& order,
                       cell::DeskState state, const std::string& message, double progress, unsigned result_files,
                       int exit_code) {
  cell::DeskReply r;
  r.submission(submission);
  r.request(request.substr(0, 255));
  r.order_id(order);
  r.state(state);
  r.message(message.substr(0, 1000));
  r.progress(progress);
  r.result_files(result_files);
  r.exit_code(exit_code);
  client.replies->write(r);
  if (state == cell::DESK_REFUSED || state == cell::DESK_DONE || state == cell::DESK_FAILED) {
    answered_.push_back({&client, r, std::chrono::steady_clock::now()});
  }
}

void RemoteDesk::refuse(Client& client, const cell::OrderRequest& request, const std::string& why, int exit_code) {
  const std::string submission = request.submission().to_string().substr(0, 64);
  log_("desk: refused " + client.id + "'s order " + submission + ": " + why);
  reply(client, submission, request.request().to_string(), "", cell::DESK_REFUSED, why, 0, 0, exit_code);
}

void RemoteDesk::take_order(Client& client, const cell::OrderRequest& request) {
  const std::string submission = request.submission().to_string();
  // Every request counts, refused or not, and is counted first: a client that sends more
  // costs the cell a refusal each, and past 4 times its rate not even that.
  const auto now = std::chrono::steady_clock::now();
  while (!client.requested_at.empty() && now - client.requested_at.front() > std::chrono::minutes(1)) client.requested_at.pop_front();
  const auto in_last_minute = static_cast<int>(client.requested_at.size());
  if (in_last_minute >= 4 * cell_.desk.orders_per_minute) {
    if (in_last_minute == 4 * cell_.desk.orders_per_minute) log_("desk: " + client.id + " floods the desk; its orders are dropped for a minute");
    client.requested_at.push_back(now);
    return;
  }
  client.requested_at.push_back(now);
  if (in_last_minute >= cell_.desk.orders_per_minute) {
    return refuse(client, request, "the desk takes " + std::to_string(cell_.desk.orders_per_minute) +
                                       " orders a minute from a client; try again in a minute", 1);
  }
  if (!good_order_id(submission)) return refuse(client, request, "a submission id is 1 to 64 of A-Z, a-z, 0-9, ., _ and -", 2);
  std::optional<FileAssembly> upload;
  {
    std::lock_guard<std::mutex> lock(client.mutex);
    if (const auto e = client.upload_errors.find(submission); e != client.upload_errors.end()) {
      const std::string why = e->second;
      client.upload_errors.erase(e);
      return refuse(client, request, why, 2);
    }
    if (const auto u = client.uploads.find(submission); u != client.uploads.end()) {
      upload = std::move(u->second);
      client.uploads.erase(u);
      client.upload_order.erase(std::find(client.upload_order.begin(), client.upload_order.end(), submission));
    }
  }
  const std::string order = client.id + "-" + submission;
  const auto orders = store_.orders();
  const auto under_way = std::count_if(orders.begin(), orders.end(), [](const auto& o) { return !o.ended(); });
  if (under_way >= cell_.desk.max_orders) {
    return refuse(client, request, "the cell has " + std::to_string(under_way) +
                                       " orders queued or under way, its limit (desk: max_orders); try again later", 1);
  }
  if (std::any_of(orders.begin(), orders.end(), [&](const auto& o) { return o.order == order; })) {
    return refuse(client, request, "the cell has an order " + order + " already: give this one another submission id", 2);
  }
  if (!upload) return refuse(client, request, "no file of this submission came", 2);
  const std::string product = request.product().to_string();
  bool has_product = false;
  for (const auto& f : request.files()) {
    const std::string name = f.name().to_string();
    const std::string* bytes = upload->complete(name);
    if (!bytes) return refuse(client, request, name + ": its chunks did not all come", 2);
    if (bytes->size() != f.size() || sha256_hex(*bytes) != f.sha256().to_string()) {
      return refuse(client, request, name + ": its size or SHA-256 is not what the order says", 2);
    }
    has_product |= name == product;
  }
  if (!has_product) return refuse(client, request, "the product " + product + " is not among the order's files", 2);
  const std::string sequence = request.sequence_strategy().to_string().empty() ? "search" : request.sequence_strategy().to_string();
  if (sequence != "search" && sequence != "paper") {
    return refuse(client, request, "sequence_strategy: '" + sequence + "' is none of search, paper", 2);
  }
  store_order(client, request, *upload, sequence);
}

// Writes the files, reads the description, hands the order to the local desk; a refusal, or
// an error, leaves nothing behind.
void RemoteDesk::store_order(Client& client, const cell::OrderRequest& request, const FileAssembly& upload,
                             const std::string& sequence) {
  const std::string submission = request.submission().to_string(), product = request.product().to_string();
  const std::string order = client.id + "-" + submission;
  const fs::path folder = cell_.state_folder() / "desk" / client.id / submission;
  std::error_code ignored;
  fs::remove_all(folder, ignored);
  try {
    for (const auto& f : request.files()) {
      const fs::path file = folder / "product" / f.name().to_string();
      fs::create_directories(file.parent_path());
      std::ofstream out(file, std::ios::binary);
      out << *upload.complete(f.name().to_string());
      if (!out.flush()) throw std::runtime_error("cannot write " + file.string());
    }
    if (const std::string error = description_error(folder / "product" / product, folder / "product"); !error.empty()) {
      fs::remove_all(folder, ignored);
      return refuse(client, request, error, 2);
    }
    fs::create_directories(folder / "out");
    state::OrderRecord record{order, "", "", (folder / "product" / product).string(), (folder / "out").string(), sequence, "linear"};
    record.quote = request.quote();
    record.client = client.id;
    record.request = request.request().to_string();
    if (!store_.submit_order(record)) {
      fs::remove_all(folder, ignored);
      return refuse(client, request, "the cell has an order " + order + " already", 2);
    }
  } catch (...) {
    fs::remove_all(folder, ignored);
    throw;
  }
  store_.journal("desk", "submitted", order, client.id + ": " + product + ", " + std::to_string(upload.bytes()) + " bytes");
  const std::string what = request.quote() ? "request for a quote " : "order ";
  log_("desk: " + client.id + "'s " + what + submission + " accepted as " + order);
  reply(client, submission, request.request().to_string(), order, cell::DESK_ACCEPTED, what + order + " accepted");
  accepted_.push_back({client.id, submission, request.request().to_string(), order, ""});
}

void RemoteDesk::follow(Accepted& a, const std::map<std::string, cell::OrderStatus>& statuses,
                        const std::vector<std::string>& queue) {
  Client& client = *clients_.at(a.client);
  if (const std::string place = OrderDesk::place_text(queue, a.order); !place.empty()) {
    const std::string now = "waits in the cell's queue, " + place;
    if (now != a.last_state) reply(client, a.submission, a.request, a.order, cell::DESK_PROGRESS, now);
    a.last_state = now;
  } else if (const auto s = statuses.find(a.order); s != statuses.end()) {
    const std::string now = std::to_string(static_cast<int>(s->second.state())) + "|" + s->second.message().to_string();
    if (now != a.last_state) {
      a.last_state = now;
      reply(client, a.submission, a.request, a.order, cell::DESK_PROGRESS, s->second.message().to_string(), s->second.progress());
    }
  }
}

void RemoteDesk::finish(Accepted& a, const state::OrderRecord& record) {
  Client& client = *clients_.at(a.client);
  std::vector<fs::path> results;
  std::error_code error;  // no folder: no results
  for (fs::directory_iterator it(fs::path(record.out), error), end; !error && it != end; it.increment(error)) {
    if (it->is_regular_file(error)) results.push_back(it->path());
  }
  const bool done = record.state == "DONE";
  reply(client, a.submission, a.request, a.order, done ? cell::DESK_DONE : cell::DESK_FAILED, done ? (record.quote ? "quoted" : "assembled") : record.reason,
        done ? 1 : 0, static_cast<unsigned>(results.size()), record.exit_code);
  // A client that stopped reading holds the desk up to 10 s, once.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (const auto& file : results) {
    if (!send_file(*client.results, a.submission, file.filename().string(), read_file_bytes(file), deadline)) {
      log_("desk: the results of " + a.order + " did not all go out to " + client.id + " (its reader fell behind)");
      return;
    }
  }
  log_("desk: " + a.order + " " + text_of(done ? cell::DESK_DONE : cell::DESK_FAILED) + "; " + std::to_string(results.size()) +
       " result files sent to " + client.id);
}

void RemoteDesk::tend() {
  // Nothing of one client's order may end cellctl up: a full disk, the database, a file.
  for (auto& [id, client] : clients_) {
    std::deque<cell::OrderRequest> requests;
    {
      std::lock_guard<std::mutex> lock(client->mutex);
      requests.swap(client->requests);
    }
    for (const auto& r : requests) {
      try {
        take_order(*client, r);
      } catch (const std::exception& e) {
        refuse(*client, r, std::string("the desk could not keep the order: ") + e.what(), 1);
      }
    }
  }
  try {
    // The database and the statuses once a round, and only while a client's order is open.
    const auto orders = accepted_.empty() ? std::vector<state::OrderRecord>{} : store_.orders();
    const auto statuses = accepted_.empty() ? std::map<std::string, cell::OrderStatus>{} : observer_.orders();
    const auto queue = OrderDesk::queue(orders);
    for (auto it = accepted_.begin(); it != accepted_.end();) {
      follow(*it, statuses, queue);
      const auto known = std::find_if(orders.begin(), orders.end(), [&](const auto& o) { return o.order == it->order; });
      if (known == orders.end() || !known->ended() || known->exit_code < 0) {
        ++it;
        continue;
      }
      try {
        finish(*it, *known);
      } catch (const std::exception& e) {
        log_("desk: the results of " + it->order + " did not all go out: " + e.what());
      }
      it = accepted_.erase(it);
    }
  } catch (const std::exception& e) {
    log_(std::string("desk: cannot follow the orders now: ") + e.what());
  }
  // A final reply stays for a client that joins late for a minute, then its instance goes:
  // the replies writer keeps no instance per submission for ever.
  while (!answered_.empty() && std::chrono::steady_clock::now() - answered_.front().at > std::chrono::minutes(1)) {
    answered_.front().client->replies->unregister(answered_.front().reply);
    answered_.pop_front();
  }
}

}  // namespace cellctl
