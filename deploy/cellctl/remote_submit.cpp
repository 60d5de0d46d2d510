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

struct Inbox {
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<cell::DeskReply> replies;
  FileAssembly results{kMaxResultBytes};
  std::string results_error;
};

}  // namespace

int submit_remote(const RemoteSubmission& s, const std::atomic<bool>& stop) {
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
    std::cerr << "error: no order desk for client " << s.client << " answered on domain " << s.dds.domain_id << " within "
              << s.wait.count() << " s (is the client in the cell's `clients:`, and its identity the cell's?)\n";
    return 3;
  }
  cell::OrderRequest request;
  request.submission(s.submission);
  request.request(request_id);
  request.product(product_name);
  request.sequence_strategy(s.sequence);
  std::uint64_t bytes = 0;
  const auto upload_by = std::chrono::steady_clock::now() + 10 * s.wait;  // the desk takes chunks at its pace
  for (const auto& [name, data] : files) {
    if (!send_file(chunks, s.submission, name, data, upload_by)) {
      std::cerr << "error: the desk took no more of " << name << "\n";
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
    std::cerr << "error: the desk did not take the order's files\n";
    return 3;
  }
  std::cout << "sent " << files.size() << " files (" << bytes << " bytes) of " << product_name << " as " << s.submission << std::endl;

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
          std::cerr << "error: the desk refused the order: " << r.message() << '\n';
          return r.exit_code();
        case cell::DESK_ACCEPTED:
          std::cout << r.message() << std::endl;
          accepted = true;
          break;
        case cell::DESK_PROGRESS:
          accepted = true;
          std::cout << "[" << r.order_id() << "] " << static_cast<int>(r.progress() * 100) << "%  " << r.message() << std::endl;
          break;
        case cell::DESK_DONE:
        case cell::DESK_FAILED:
          end = r;
          break;
      }
    }
    if (!inbox.results_error.empty()) {
      std::cerr << "error: the results came broken: " << inbox.results_error << '\n';
      return 1;
    }
    if (end && inbox.results.complete_files() >= end->result_files()) break;
    // An answer comes within --wait; once accepted, progress with every step (an order may take
    // long, a step not 5 minutes); results within --wait of the end.
    const auto silence = accepted && !end ? std::max<std::chrono::seconds>(s.wait, 300s) : s.wait;
    if (std::chrono::steady_clock::now() - last_heard > silence) {
      std::cerr << "error: the desk went silent " << (end ? "before all results came" : "") << '\n';
      return 3;
    }
  }
  if (!end) {
    std::cout << "stopped following; the order goes on in the cell\n";
    return 0;
  }
  fs::create_directories(s.out);
  for (const auto& [name, data] : inbox.results.files()) {
    const fs::path file = fs::path(s.out) / fs::path(name).filename();
    std::ofstream out(file, std::ios::binary);
    if (!(out << data).flush()) {
      std::cerr << "error: cannot write " << file.string() << '\n';
      return 1;
    }
  }
  if (end->state() == cell::DESK_DONE) {
    std::cout << "order " << end->order_id() << " done: " << s.out << "/report.html, " << s.out << "/plan.json, " << s.out << "/animation.gltf\n";
  } else {
    std::cerr << "error: order " << end->order_id() << ": " << end->message() << '\n';
  }
  return end->exit_code();
}

}  // namespace cellctl
