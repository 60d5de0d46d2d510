// Stress of a state reader whose writers lapse and come back and whose instances end and are
// written again, as a loaded cell's are: two writer processes, each stopped (SIGSTOP) past its
// liveliness lease at random moments and continued, while it updates, unregisters and writes
// again its instances and replaces its writers (dds::Writer: its refresh writes every live instance at a third of the
// lease). The reader is either dds::Reader (`--reader ours`: ended instances are read, and
// taken in a sweep seconds later) or a reader that takes each ended instance as soon as it
// sees it (`--reader take`, what dds::Reader did before 12-07).
//
// Why: Fast DDS 2.9.1 walks a reader's instance map without the reader's lock when a writer
// lapses or leaves (DataReaderHistory::writer_not_alive), and a take that empties an ended
// instance erases it from that map. This measures how often a reader process dies of it.
//
// Run: build/release/bin/stress_ended_instances --reader take|ours [--seconds 60] [--instances 50] [--domain 210]
// It prints what the reader heard and exits 0; a reader that crashed ends with its signal.

#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <sys/prctl.h>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include "capabilitiesPubSubTypes.h"
#include "services/dds/endpoints.hpp"
#include "services/dds/participant.hpp"
#include "tests/support/child_process.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using Capability = cell::Capability;
using CapabilityWriter = dds::Writer<Capability, cell::CapabilityPubSubType>;
using CapabilityReader = dds::Reader<Capability, cell::CapabilityPubSubType>;

constexpr double kLeaseS = 0.2;
constexpr int kWritersPerProcess = 3;
const std::string kTopic = "stress/capabilities";

dds::QosSettings quick() {
  dds::QosSettings settings;
  settings.liveliness_lease_s = kLeaseS;
  return settings;
}

Capability capability(const std::string& id, int count) {
  Capability c;
  c.resource_id(id);
  c.kind("buffer");
  c.stock().push_back(cell::PartStock());
  c.stock()[0].part_type("Peg");
  c.stock()[0].count(count);
  return c;
}

// A writer process: updates a random instance every 2 ms; one in ten updates unregisters the
// instance instead, and the next update of it writes it again. Every 0.2 s one of its writers
// is deleted and a new one writes its instances (a twin that ends and the next one).
int write_until_killed(const dds::ParticipantSettings& settings, int process, int instances) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // a reader that crashed leaves no writer, stopped or not, behind
  auto participant = dds::make_participant("stress-writer", settings);
  std::vector<std::unique_ptr<CapabilityWriter>> writers;
  for (int w = 0; w < kWritersPerProcess; ++w) {
    writers.push_back(std::make_unique<CapabilityWriter>(participant, kTopic, dds::TopicKind::state, quick()));
  }
  const auto id = [&](int w, int i) { return "p" + std::to_string(process) + "-w" + std::to_string(w) + "-i" + std::to_string(i); };
  for (int w = 0; w < kWritersPerProcess; ++w) {
    for (int i = 0; i < instances; ++i) writers[w]->write(capability(id(w, i), 0));
  }
  std::mt19937 random(static_cast<unsigned>(process));
  std::uniform_int_distribution<int> writer_of(0, kWritersPerProcess - 1), instance_of(0, instances - 1),
      tenth(0, 9);
  for (int count = 1;; ++count) {
    const int w = writer_of(random), i = instance_of(random);
    if (count % 100 == 0) {  // every 0.2 s a writer leaves and another takes its instances
      writers[w].reset();
      writers[w] = std::make_unique<CapabilityWriter>(participant, kTopic, dds::TopicKind::state, quick());
      for (int k = 0; k < instances; ++k) writers[w]->write(capability(id(w, k), count));
    }
    if (tenth(random) == 0) {
      writers[w]->unregister(capability(id(w, i), 0));
    } else {
      writers[w]->write(capability(id(w, i), count));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// What dds::Reader did before 12-07: read new samples of live instances, take ended ones at once.
class TakingReader : private fdds::DataReaderListener {
 public:
  TakingReader(dds::ParticipantPtr participant, std::atomic<long>& heard, std::atomic<long>& gone)
      : participant_(std::move(participant)), heard_(heard), gone_(gone) {
    subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    reader_ = subscriber_->create_datareader(dds::topic_on<cell::CapabilityPubSubType>(*participant_, kTopic),
                                             dds::reader_qos(dds::TopicKind::state, quick()), this);
  }
  ~TakingReader() override {
    reader_->set_listener(nullptr);
    while (requests_ != 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    subscriber_->delete_datareader(reader_);
    participant_->delete_subscriber(subscriber_);
  }

 private:
  void on_data_available(fdds::DataReader* reader) override { drain(reader); }
  void on_subscription_matched(fdds::DataReader* reader, const fdds::SubscriptionMatchedStatus&) override { drain(reader); }
  void on_liveliness_changed(fdds::DataReader* reader, const fdds::LivelinessChangedStatus&) override { drain(reader); }
  void drain(fdds::DataReader* reader) {
    if (requests_.fetch_add(1) != 0) return;
    int served = 0;
    do {
      served = requests_.load();
      fdds::LoanableSequence<Capability> samples;
      fdds::SampleInfoSeq infos;
      const auto ok = ReturnCode_t::RETCODE_OK;
      while (reader->read(samples, infos, fdds::LENGTH_UNLIMITED, fdds::NOT_READ_SAMPLE_STATE, fdds::ANY_VIEW_STATE,
                          fdds::ALIVE_INSTANCE_STATE) == ok) {
        heard_ += infos.length();
        reader->return_loan(samples, infos);
      }
      while (reader->take(samples, infos, fdds::LENGTH_UNLIMITED, fdds::ANY_SAMPLE_STATE, fdds::ANY_VIEW_STATE,
                          fdds::NOT_ALIVE_INSTANCE_STATE) == ok) {
        gone_ += infos.length();
        reader->return_loan(samples, infos);
      }
    } while (requests_.fetch_sub(served) != served);
  }

  dds::ParticipantPtr participant_;
  std::atomic<long>& heard_;
  std::atomic<long>& gone_;
  std::atomic<int> requests_{0};
  fdds::Subscriber* subscriber_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
};

}  // namespace

int main(int argc, char** argv) {
  std::string mode = "ours";
  int seconds = 60, domain = 210, instances = 50;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--reader") mode = argv[i + 1];
    if (key == "--seconds") seconds = std::stoi(argv[i + 1]);
    if (key == "--domain") domain = std::stoi(argv[i + 1]);
    if (key == "--instances") instances = std::stoi(argv[i + 1]);  // per writer, three writers a process
  }
  if (mode != "ours" && mode != "take") {
    std::cerr << "--reader: 'ours' or 'take', not '" << mode << "'\n";
    return 2;
  }
  const dds::ParticipantSettings settings{domain, true, {}};
  // The writers are forked before this process starts a thread.
  std::vector<std::unique_ptr<test::ChildProcess>> writers;
  for (int p = 0; p < 2; ++p) {
    writers.push_back(std::make_unique<test::ChildProcess>([&settings, p, instances] { return write_until_killed(settings, p, instances); }));
  }
  std::atomic<long> heard{0}, gone{0};
  auto participant = dds::make_participant("stress-reader", settings);
  std::unique_ptr<CapabilityReader> ours;
  std::unique_ptr<TakingReader> taking;
  if (mode == "ours") {
    ours = std::make_unique<CapabilityReader>(participant, kTopic, dds::TopicKind::state,
                                              [&](const Capability&) { ++heard; }, [&](const Capability&) { ++gone; }, quick());
  } else {
    taking = std::make_unique<TakingReader>(participant, heard, gone);
  }

  // Each writer process stopped for 1.5 to 4 leases every 0.3 to 1 s, independently.
  std::atomic<bool> running{true};
  std::vector<std::thread> stoppers;
  for (int p = 0; p < 2; ++p) {
    stoppers.emplace_back([&, p] {
      std::mt19937 random(static_cast<unsigned>(100 + p));
      std::uniform_int_distribution<int> pause_ms(300, 1000), stop_ms(static_cast<int>(1500 * kLeaseS), static_cast<int>(4000 * kLeaseS));
      while (running) {
        std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms(random)));
        ::kill(writers[p]->pid(), SIGSTOP);
        std::this_thread::sleep_for(std::chrono::milliseconds(stop_ms(random)));
        ::kill(writers[p]->pid(), SIGCONT);
      }
    });
  }
  std::this_thread::sleep_for(std::chrono::seconds(seconds));
  running = false;
  for (auto& s : stoppers) s.join();
  std::cout << "reader " << mode << ", " << seconds << " s: " << heard << " samples heard, " << gone << " ends\n";
  writers.clear();
  ours.reset();
  taking.reset();
  return 0;
}
