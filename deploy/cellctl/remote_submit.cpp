#include "deploy/cellctl/remote_submit.hpp"

#include <condition_variable>
#include <deque>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <thread>

#include "deploy/cellctl/file_transfer.hpp"
#include "twin/description/automationml/automationml_description.hpp"
#include "twin/model/source_ref.hpp"

namespace cellctl {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

constexpr std::uint64_t kMaxResultBytes = 512'000'000;

// The product file and the mesh files it names, by their names relative to its folder. A
// description the reader refuses goes alone: the desk answers with the reader's error.
std::map<std::string, std::string> files_of(const fs::path& product) {
  const fs::path folder = fs::absolute(product).parent_path();
  std::set<fs::path> files{fs::absolute(product)};
  try {
    for (const auto& item : twin::AutomationMLDescription(product).items()) {
      if (const auto* part = std::get_if<twin::CreatePartItem>(&item); part && part->mesh) files.insert(part->mesh->file);
    }
  } catch (const twin::DescriptionError&) {
  }
  std::map<std::string, std::string> out;
  for (const auto& f : files) out[fs::relative(f, folder).generic_string()] = read_file_bytes(f);
  return out;
}

// One whole line at a time: several submissions may print at once (cellctl quote).
void say(const RemoteSubmission& s, std::ostream& to, const std::string& line) {
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  to << s.label << line << std::endl;
}

struct Inbox {
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<cell::DeskReply> replies;
  FileAssembly results{kMaxResultBytes};
  std::string results_error;
};

}  // namespace

int submit_remote(const RemoteSubmission& s, const std::atomic<bool>& stop, std::string* error) {
  const auto fail = [&](const std::string& why) {
    say(s, std::cerr, "error: " + why);
    if (error) *error = why;
  };
  const auto files = files_of(s.product);
  const std::string product_name = fs::path(s.product).filename().string();
  // Replies are kept per submission id for late readers: this request's carry its id.
  std::random_device random;
  const std::string request_id = std::to_string(random()) + std::to_string(random());
  Inbox inbox;
  auto participant = dds::make_participant("client-" + s.client, s.dds);
  dds::Reader<cell::DeskReply, cell::DeskReplyPubSubType> replies(
      participant, desk_topic("replies", s.client), dds::TopicKind::state, [&](const cell::DeskReply& r) {
        if (r.submission().to_string() != s.submission || r.request().to_string() != request_id) return;
        std::lock_guard<std::mutex> lock(inbox.mutex);
        inbox.replies.push_back(r);
        inbox.changed.notify_all();
      });
  dds::Reader<cell::FileChunk, cell::FileChunkPubSubType> results(
      participant, desk_topic("results", s.client), dds::TopicKind::events,
      [&](const cell::FileChunk& c) {
        if (c.submission().to_string() != s.submission) return;
        std::lock_guard<std::mutex> lock(inbox.mutex);
        try {
          if (const std::string why = inbox.results.add(c); !why.empty()) inbox.results_error = why;
        } catch (const std::exception& e) {  // on a DDS thread: nothing may escape
          inbox.results_error = e.what();
        }
        inbox.changed.notify_all();
      },
      {}, chunk_qos());
  ChunkWriter chunks(participant, desk_topic("files", s.client), dds::TopicKind::events, chunk_qos());
  dds::Writer<cell::OrderRequest, cell::OrderRequestPubSubType> orders(participant, desk_topic("orders", s.client),
                                                                       dds::TopicKind::events);
  const auto answer_by = std::chrono::steady_clock::now() + s.wait;
  const auto left = [&] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(answer_by - std::chrono::steady_clock::now());
  };
  if (!chunks.wait_for_readers(1, left()) || !orders.wait_for_readers(1, left())) {
    fail("no order desk for client " + s.client + " answered on domain " + std::to_string(s.dds.domain_id) +
                          " within " + std::to_string(s.wait.count()) +
                          " s (is the client in the cell's `clients:`, and its identity the cell's?)");
    return 3;
  }
  cell::OrderRequest request;
  request.submission(s.submission);
  request.request(request_id);
  request.product(product_name);
  request.sequence_strategy(s.sequence);
  request.quote(s.quote);
  std::uint64_t bytes = 0;
  const auto upload_by = std::chrono::steady_clock::now() + 10 * s.wait;  // the desk takes chunks at its pace
  for (const auto& [name, data] : files) {
    if (!send_file(chunks, s.submission, name, data, upload_by)) {
      fail("the desk took no more of " + name);
      return 3;
    }
    cell::FileDigest d;
    d.name(name);
    d.size(data.size());
    d.sha256(sha256_hex(data));
    request.files().push_back(d);
    bytes += data.size();
  }
  // The order on its own topic must not overtake the last chunks on theirs.
  if (!chunks.wait_for_acknowledgments(std::chrono::duration_cast<std::chrono::milliseconds>(upload_by - std::chrono::steady_clock::now())) ||
      !orders.write(request)) {
    fail("the desk did not take the order's files");
    return 3;
  }
  say(s, std::cout, "sent " + std::to_string(files.size()) + " files (" + std::to_string(bytes) + " bytes) of " + product_name +
                        " as " + s.submission);

  auto last_heard = std::chrono::steady_clock::now();
  std::optional<cell::DeskReply> end;
  bool accepted = false;
  std::unique_lock<std::mutex> lock(inbox.mutex);
  while (!stop) {
    inbox.changed.wait_for(lock, 100ms);
    while (!inbox.replies.empty() && !end) {
      const cell::DeskReply r = inbox.replies.front();
      inbox.replies.pop_front();
      last_heard = std::chrono::steady_clock::now();
      switch (r.state()) {
        case cell::DESK_REFUSED:
          fail("the desk refused the order: " + r.message().to_string());
          return r.exit_code();
        case cell::DESK_ACCEPTED:
          say(s, std::cout, r.message().to_string());
          accepted = true;
          break;
        case cell::DESK_PROGRESS:
          // Replies are a state topic (the last per submission): the acceptance may have been
          // replaced by the first progress before this reader took it (the secure cell's test
          // under ASan saw that). Progress says it was accepted.
          if (!accepted) {
            say(s, std::cout, std::string(s.quote ? "request for a quote " : "order ") + r.order_id().to_string() +
                                  " accepted");
          }
          accepted = true;
          say(s, std::cout, "[" + r.order_id().to_string() + "] " + std::to_string(static_cast<int>(r.progress() * 100)) + "%  " +
                                r.message().to_string());
          break;
        case cell::DESK_DONE:
        case cell::DESK_FAILED:
          end = r;
          break;
      }
    }
    if (!inbox.results_error.empty()) {
      fail("the results came broken: " + inbox.results_error);
      return 1;
    }
    if (end && inbox.results.complete_files() >= end->result_files()) break;
    // An answer comes within --wait; once accepted, progress with every step (an order may take
    // long, a step not 5 minutes); results within --wait of the end.
    const auto silence = accepted && !end ? std::max<std::chrono::seconds>(s.wait, 300s) : s.wait;
    if (std::chrono::steady_clock::now() - last_heard > silence) {
      fail(std::string("the desk went silent") + (end ? " before all results came" : ""));
      return 3;
    }
  }
  if (!end) {
    say(s, std::cout, "stopped following; the order goes on in the cell");
    return 0;
  }
  fs::create_directories(s.out);
  for (const auto& [name, data] : inbox.results.files()) {
    const fs::path file = fs::path(s.out) / fs::path(name).filename();
    std::ofstream out(file, std::ios::binary);
    if (!(out << data).flush()) {
      fail("cannot write " + file.string());
      return 1;
    }
  }
  if (end->state() != cell::DESK_DONE) {
    fail("order " + end->order_id().to_string() + ": " + end->message().to_string());
  } else if (s.quote) {
    say(s, std::cout, "quote " + end->order_id().to_string() + ": " + s.out + "/quote.json, " + s.out + "/report.html");
  } else {
    say(s, std::cout, "order " + end->order_id().to_string() + " done: " + s.out + "/report.html, " + s.out + "/plan.json, " +
                          s.out + "/animation.gltf");
  }
  return end->exit_code();
}

}  // namespace cellctl
