#pragma once
// Typed DDS writers and readers on a participant, with the QoS of their topic kind.
// T is a fastddsgen type, PubSubType its generated TypeSupport class.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <type_traits>
#include <utility>
#include <vector>
#include <malloc.h>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "services/dds/liveliness_keeper.hpp"
#include "services/dds/participant.hpp"
#include "services/dds/qos.hpp"
#include "services/dds/twin_bindings.hpp"

namespace dds {

namespace fdds = eprosima::fastdds::dds;

// Each resource reads its commands from a topic of its own: no process receives (and keeps
// in its reader) another resource's commands.
inline std::string command_topic(const std::string& resource_id) { return "cell/commands/" + resource_id; }

// Whether the participant has DDS-Security access control (services/dds/security.hpp).
inline bool access_controlled(const fdds::DomainParticipant& participant) {
  for (const auto& p : participant.get_qos().properties().properties()) {
    if (p.name() == "dds.sec.access.plugin") return true;
  }
  return false;
}

// Topics every resource writes about itself (its capability, its commands' events). Each
// writes them in a DDS partition named after its id, and their readers read every partition
// (every_partition()):
// DDS-Security permissions then let a resource write its own and no other's
// (deploy/cellctl/pki_policy.cpp).
inline bool owned_topic(const std::string& topic) { return topic == "cell/capabilities" || topic == "cell/command_events"; }

// Topics a twin writes for its order. Under DDS-Security each twin writes them in the
// partition of its own identity, and a reader takes a sample only from the twin its order is
// bound to (twin_bindings.hpp). The commands to a buffer come from robots, whose readers say
// who speaks for them (NodeConfig::commanded_by_destination).
inline bool order_scoped_topic(const std::string& topic) {
  return topic == "cell/orders/status" || topic == "cell/orders/result" || topic == "cell/negotiation/calls" ||
         topic == "cell/negotiation/awards" || topic == "cell/negotiation/releases" || topic == "cell/cancel_requests" ||
         topic.rfind("cell/commands/", 0) == 0;
}

template <class T, class = void>
struct has_resource_id : std::false_type {};
template <class T>
struct has_resource_id<T, std::void_t<decltype(std::declval<const T&>().resource_id())>> : std::true_type {};
template <class T, class = void>
struct has_order_id : std::false_type {};
template <class T>
struct has_order_id<T, std::void_t<decltype(std::declval<const T&>().order_id())>> : std::true_type {};

// Whom a sample speaks for (Reader): its writer must write in the partition of that name (a
// resource's id, a twin's identity). nullopt: not known yet; the sample waits for it.
template <class T>
using Speaker = std::function<std::optional<std::string>(const T&)>;

// Settings with the partition(s) `owner` writes an owned topic in.
inline QosSettings owned_by(std::vector<std::string> owner, QosSettings settings = {}) {
  settings.partitions = std::move(owner);
  return settings;
}

// A reader of an owned topic: every resource's partition; and the default one ("*" matches no
// writer there) unless access control is on: DDS-Security checks a writer's partition and
// topic each against all of a grant's rules, so a resource's grant, which has the default
// partition for its other topics, would let it write a capability there.
inline std::vector<std::string> every_partition(const fdds::DomainParticipant& participant) {
  if (access_controlled(participant)) return {"*"};
  return {"*", ""};
}

template <class Qos>
Qos with_partitions(Qos qos, const std::vector<std::string>& partitions) {
  for (const auto& p : partitions) qos.partition().push_back(p.c_str());
  return qos;
}

// Why Fast DDS refused an endpoint, as far as we know: under DDS-Security, the identity's
// permissions (Fast DDS logs which rule), else nothing more to say.
inline std::string refusal_reason(const fdds::DomainParticipant& participant) {
  return access_controlled(participant) ? ": this identity's DDS-Security permissions do not allow it" : "";
}

// The topic of that name on the participant, created (and its type registered) if needed.
template <class PubSubType>
fdds::Topic* topic_on(fdds::DomainParticipant& participant, const std::string& name) {
  fdds::TypeSupport type(new PubSubType());
  type.register_type(&participant);
  if (auto* existing = participant.find_topic(name, eprosima::fastrtps::Duration_t(0, 0))) return existing;
  fdds::Topic* topic = participant.create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (!topic) throw std::runtime_error("cannot create topic " + name + refusal_reason(participant));
  return topic;
}

template <class T, class PubSubType>
class Writer : private fdds::DataWriterListener {
 public:
  // Under DDS-Security, an order's topics (order_scoped_topic) go in the partition of the
  // writer's identity unless `settings` names others.
  Writer(ParticipantPtr participant, const std::string& topic, TopicKind kind, const QosSettings& settings = {})
      : participant_(std::move(participant)) {
    std::vector<std::string> partitions = settings.partitions;
    if (partitions.empty() && order_scoped_topic(topic) && access_controlled(*participant_)) {
      partitions = {security_identity(*participant_)};
    }
    publisher_ = participant_->create_publisher(with_partitions(fdds::PUBLISHER_QOS_DEFAULT, partitions));
    writer_ = publisher_->create_datawriter(topic_on<PubSubType>(*participant_, topic), writer_qos(kind, settings), this);
    if (!writer_) throw std::runtime_error("cannot create a writer on " + topic + refusal_reason(*participant_));
    if (kind == TopicKind::state) {
      kept_alive_ = true;
      LivelinessKeeper::of_this_process().keep(
          this, std::chrono::milliseconds(static_cast<long>(settings.liveliness_lease_s * 1000 / 3)), [this] { refresh(); });
    }
  }
  // A matched callback already under way finishes first; later ones find the writer closed.
  ~Writer() override {
    if (kept_alive_) LivelinessKeeper::of_this_process().forget(this);
    writer_->set_listener(nullptr);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    publisher_->delete_datawriter(writer_);
    participant_->delete_publisher(publisher_);
  }
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // State topics: the sample is kept for the next refresh before it is written (a reader's
  // callback in this process may write here during the write), and kept even if the write
  // fails: the refresh writes it then.
  bool write(const T& sample) {
    if (!kept_alive_) return writer_->write(const_cast<T*>(&sample));
    std::lock_guard<std::recursive_mutex> lock(last_mutex_);
    last_.insert_or_assign(instance_of(sample), sample);
    return writer_->write(const_cast<T*>(&sample));
  }

  // Keyed topics: the instance of `sample` ends here (late readers no longer get it).
  void unregister(const T& sample) {
    std::lock_guard<std::recursive_mutex> lock(last_mutex_);
    last_.erase(instance_of(sample));
    writer_->unregister_instance(const_cast<T*>(&sample), fdds::HANDLE_NIL);
  }

  // Until every matched reader acknowledged every sample written (at most `timeout`).
  bool wait_for_acknowledgments(std::chrono::milliseconds timeout) {
    return writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(static_cast<double>(timeout.count()) / 1000)) ==
           ReturnCode_t::RETCODE_OK;
  }

  // Waits until at least `readers` readers have matched; never sleep a guessed time.
  bool wait_for_readers(int readers, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return matched_changed_.wait_for(lock, timeout, [&] { return matched_ >= readers; });
  }

  // Waits until some reader has matched and no match came or went for `quiet` (discovery of
  // the participants already there is done), at most `timeout`; the readers matched.
  int wait_for_settled_readers(std::chrono::milliseconds quiet, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::unique_lock<std::mutex> lock(mutex_);
    while (std::chrono::steady_clock::now() < deadline) {
      const auto settled_at = std::min(matched_at_ + quiet, deadline);
      if (matched_ > 0 && std::chrono::steady_clock::now() >= matched_at_ + quiet) break;
      matched_changed_.wait_until(lock, matched_ > 0 ? settled_at : deadline);
    }
    return matched_;
  }

 private:
  // State topics, from the LivelinessKeeper: each instance's last sample written again, which
  // asserts the writer's liveliness too. A reader that found the writer's liveliness lapsed
  // (this process or the reader's starved past the lease, not dead) has its state back so;
  // Fast DDS keeps the instances NOT_ALIVE until the next write. Readers let a repeated
  // sample through only after its instance's end (Reader::repeats).
  // A write delivers to this process's readers on the writing thread: their callbacks may
  // write or unregister here meanwhile (hence a recursive lock, and each instance looked up
  // afresh).
  void refresh() {
    std::lock_guard<std::recursive_mutex> lock(last_mutex_);
    if (last_.empty()) writer_->assert_liveliness();
    std::vector<fdds::InstanceHandle_t> instances;
    for (const auto& kept : last_) instances.push_back(kept.first);
    for (const auto& instance : instances) {
      const auto it = last_.find(instance);
      if (it != last_.end()) writer_->write(&it->second);
    }
  }

  fdds::InstanceHandle_t instance_of(const T& sample) {
    fdds::InstanceHandle_t handle;
    if (key_type_.m_isGetKeyDefined) key_type_.getKey(const_cast<T*>(&sample), &handle, false);
    return handle;
  }

  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& status) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return;
    matched_ = status.current_count;
    matched_at_ = std::chrono::steady_clock::now();
    matched_changed_.notify_all();  // under the lock: the destructor cannot take the condition away meanwhile
  }

  ParticipantPtr participant_;
  fdds::Publisher* publisher_ = nullptr;
  fdds::DataWriter* writer_ = nullptr;
  bool kept_alive_ = false;
  std::recursive_mutex last_mutex_;  // a refresh never writes an instance's older sample after its newer one
  PubSubType key_type_;
  std::map<fdds::InstanceHandle_t, T> last_;  // state topics: each live instance's last sample
  std::mutex mutex_;
  std::condition_variable matched_changed_;
  int matched_ = 0;
  std::chrono::steady_clock::time_point matched_at_ = std::chrono::steady_clock::now();
  bool closed_ = false;
};

// A writer whose samples come late rather than never while a reader is slow for a while.
// A reliable KEEP_ALL writer whose readers have not acknowledged `max_queued` samples waits
// max_blocking_time for room and then fails the write: under a flood, beside a reader starved
// of CPU, a command's final event was lost so. The outbox keeps such samples, in order, and
// writes them again before its next sample and on flush(). Bounded: past `capacity` kept
// samples it refuses more. Thread-safe.
template <class T, class PubSubType>
class Outbox {
 public:
  Outbox(ParticipantPtr participant, const std::string& topic, TopicKind kind, const QosSettings& settings = {},
         std::size_t capacity = 4096)
      : writer_(std::move(participant), topic, kind, settings), capacity_(capacity) {}

  // True when the sample was written or is kept to be written; false when the outbox is full.
  bool write(const T& sample) {
    std::lock_guard<std::mutex> lock(mutex_);
    flush_locked();
    if (kept_.empty() && writer_.write(sample)) return true;
    if (kept_.size() >= capacity_) return false;
    kept_.push_back(sample);
    return true;
  }
  // Writes what was kept while there is room; the samples still kept.
  std::size_t flush() {
    std::lock_guard<std::mutex> lock(mutex_);
    flush_locked();
    return kept_.size();
  }

  Writer<T, PubSubType>& writer() { return writer_; }

 private:
  void flush_locked() {
    if (kept_.empty()) return;
    while (!kept_.empty() && writer_.write(kept_.front())) kept_.pop_front();
    if (kept_.empty()) {
      // A backlog of bounded samples (a command event is 2.3 kB) is megabytes: given back to
      // the system once it is out, so that a flood leaves no trace in resident memory.
      std::deque<T>().swap(kept_);
      ::malloc_trim(0);
    }
  }

  Writer<T, PubSubType> writer_;
  std::size_t capacity_;
  std::mutex mutex_;
  std::deque<T> kept_;
};

template <class T, class PubSubType>
class Reader : private fdds::DataReaderListener {
 public:
  // Called on Fast DDS's listener thread: `on_sample` for each new sample; on state topics,
  // `on_gone` with an instance's last sample when its writers are gone (liveliness lost,
  // process ended) or it was disposed.
  // `speaker`: the resource a sample speaks for, whose partition its writer must write in for
  // it to count under access control (owned topics: the sample's resource_id). The reader then
  // reads every partition.
  // An order's topics (order_scoped_topic), under access control: the twin the sample's order
  // is bound to; a sample whose order has no binding yet waits for it (at most kHeld).
  Reader(ParticipantPtr participant, const std::string& topic, TopicKind kind, std::function<void(const T&)> on_sample,
         std::function<void(const T&)> on_gone = {}, const QosSettings& settings = {}, Speaker<T> speaker = {})
      : participant_(std::move(participant)), kind_(kind), speaker_(std::move(speaker)), on_sample_(std::move(on_sample)),
        on_gone_(std::move(on_gone)) {
    if constexpr (has_resource_id<T>::value) {
      if (!speaker_ && owned_topic(topic)) speaker_ = [](const T& s) { return s.resource_id().to_string(); };
    }
    if constexpr (has_order_id<T>::value) {
      if (!speaker_ && order_scoped_topic(topic) && access_controlled(*participant_)) {
        bindings_ = twin_bindings(participant_);
        speaker_ = [b = bindings_.get()](const T& s) { return b->identity_of(s.order_id().to_string()); };
      }
    }
    subscriber_ = participant_->create_subscriber(with_partitions(
        fdds::SUBSCRIBER_QOS_DEFAULT, settings.partitions.empty() && speaker_ ? every_partition(*participant_)
                                                                              : settings.partitions));
    check_writers_ = speaker_ && access_controlled(*participant_);
    topic_ = topic;
    reader_ = subscriber_->create_datareader(topic_on<PubSubType>(*participant_, topic), reader_qos(kind, settings), this);
    if (!reader_) throw std::runtime_error("cannot create a reader on " + topic + refusal_reason(*participant_));
    // A binding that comes lets the samples waiting for it go on (one that came before
    // listen() too).
    if (bindings_) {
      listener_ = bindings_->listen([this] { drain(reader_); });
      drain(reader_);
    }
  }
  // A drain already under way finishes first; later callbacks find the reader closed.
  ~Reader() override {
    reader_->set_listener(nullptr);
    closed_ = true;
    if (bindings_) bindings_->forget(listener_);  // a call under way ends first
    while (requests_ != 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    subscriber_->delete_datareader(reader_);
    participant_->delete_subscriber(subscriber_);
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

 private:
  // The reader comes with the callback: during create_datareader a writer of this process
  // may deliver to it already, before reader_ is set.
  void on_data_available(fdds::DataReader* reader) override { drain(reader); }
  // A writer that leaves or dies changes its instances' state; Fast DDS 2.9 does not always
  // announce that through on_data_available, so look then too.
  void on_subscription_matched(fdds::DataReader* reader, const fdds::SubscriptionMatchedStatus& status) override {
    if (status.current_count_change < 0) announce_ends(reader);
  }
  // Any change marks the ends to look for: Fast DDS 2.9.1 may merge a lapse into a
  // concurrent update of the status, and the next drain finds it. Only a lapse drains from
  // here: draining on every change (writers coming alive too) left readers deaf for seconds
  // beside a CPU hog under ThreadSanitizer (5 of 66 runs against 0 of 66, docs/topics.md).
  void on_liveliness_changed(fdds::DataReader* reader, const fdds::LivelinessChangedStatus& status) override {
    ends_announced_ = true;
    if (status.not_alive_count_change > 0) drain(reader);
  }
  // Instances whose sample was read may have ended without a sample: the drain looks at them.
  void announce_ends(fdds::DataReader* reader) {
    ends_announced_ = true;
    drain(reader);
  }

  // Callbacks come on several Fast DDS threads, some holding the reader's own lock (data)
  // and some not (matching, liveliness). One thread drains at a time, and the others never
  // wait for it: they count a request and leave, and the draining thread goes round again
  // until no request is left. (A mutex here deadlocked against Fast DDS's reader lock: one
  // thread held it and waited for ours, ours waited for it in return_loan.)
  void drain(fdds::DataReader* reader) {
    if (requests_.fetch_add(1) != 0) return;  // the draining thread will go round again
    int served = 0;
    do {
      served = requests_.load();
      if (!closed_) drain_once(reader);
    } while (requests_.fetch_sub(served) != served);
  }

  // Event topics: take every new sample. State topics: read new samples but keep the last
  // one per instance, so that when an instance's writers are gone (its state turns
  // NOT_ALIVE) the kept sample tells which instance it was. New samples are read whatever
  // their instance's state: one that came just before its writer's liveliness lapsed is
  // delivered before the instance's end, not lost in it. A read or take gives at most
  // max_samples_per_read (32): each goes round until nothing is left, or what came while
  // another thread's callback was folded into this drain would wait for the next sample
  // (under TSan, the last of a burst's 9 834 command events waited for ever so).
  void drain_once(fdds::DataReader* reader) {
    deliver_held_if_bound();
    fdds::LoanableSequence<T> samples;
    fdds::SampleInfoSeq infos;
    bool ended = ends_announced_.exchange(false);  // a writer lapsed or left
    const auto visit = [&](auto&& each, bool as_alive = false) {
      for (fdds::LoanableCollection::size_type i = 0; i < infos.length(); ++i) {
        if (infos[i].instance_state != fdds::ALIVE_INSTANCE_STATE) ended = true;
        if (!infos[i].valid_data) {
          // An instance its writer unregistered or disposed, whose end replaced its last
          // sample: the end is said with the sample last delivered.
          if (!as_alive && infos[i].instance_state != fdds::ALIVE_INSTANCE_STATE) say_end_of_delivered(infos[i].instance_handle);
          continue;
        }
        // A new sample: its instance lived again since the end last said of it.
        if (as_alive) {
          ended_.erase(infos[i].instance_handle);
          say_missed_end(infos[i]);
        }
        // A binding that came during this drain: what waited for it goes first, in order.
        deliver_held_if_bound();
        const Source source{infos[i].sample_identity.writer_guid(), infos[i].instance_handle,
                            !as_alive && infos[i].instance_state != fdds::ALIVE_INSTANCE_STATE, generation(infos[i])};
        // A NEW view: the instance's first sample, or its first since it ended (its writer
        // lapsed or unregistered it), whatever was delivered before.
        if (infos[i].view_state != fdds::NEW_VIEW_STATE && repeats(samples[i], source)) continue;
        const Verdict v = from_its_owner(samples[i], source);
        if (v == Verdict::take) {
          remember(samples[i], source);
          each(samples[i]);
        }
        if (v == Verdict::hold) hold(samples[i], source);
      }
      reader->return_loan(samples, infos);
    };
    const auto ok = ReturnCode_t::RETCODE_OK;
    if (kind_ == TopicKind::events) {
      while (!closed_ && reader->take(samples, infos) == ok) visit([&](const T& s) { if (on_sample_) on_sample_(s); });
      return;
    }
    while (!closed_ && reader->read(samples, infos, fdds::LENGTH_UNLIMITED, fdds::NOT_READ_SAMPLE_STATE) == ok) {
      visit([&](const T& s) { if (on_sample_) on_sample_(s); }, /*as_alive=*/true);
    }
    // A topic without a key has one instance, which Fast DDS never erases: its end is taken.
    if (!keyed_) {
      while (!closed_ && reader->take(samples, infos, fdds::LENGTH_UNLIMITED, fdds::ANY_SAMPLE_STATE, fdds::ANY_VIEW_STATE,
                                      fdds::NOT_ALIVE_INSTANCE_STATE) == ok) {
        visit([&](const T& s) { if (on_gone_) on_gone_(s); });
      }
      return;
    }
    // Each ended instance's end, said once; the instance is read, not taken (sweep_ended).
    // Looked for when something ended, and at each sweep in case an announcement was lost.
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_sweep_) ended = true;
    fdds::InstanceHandle_t previous = fdds::HANDLE_NIL;
    while (ended && !closed_ && reader->read_next_instance(samples, infos, fdds::LENGTH_UNLIMITED, previous, fdds::ANY_SAMPLE_STATE,
                                                  fdds::ANY_VIEW_STATE, fdds::NOT_ALIVE_INSTANCE_STATE) == ok) {
      previous = infos[0].instance_handle;
      if (!ended_.emplace(previous, now).second) {
        reader->return_loan(samples, infos);
        continue;
      }
      visit([&](const T& s) { if (on_gone_) on_gone_(s); });
    }
    if (!closed_) sweep_ended(reader, now);
  }

  // Why ended instances are taken in a sweep, not as their end is said: Fast DDS 2.9.1 walks
  // a reader's instance map without the reader's lock when a writer lapses or leaves
  // (DataReaderHistory::writer_not_alive; locked upstream in 2.14.6), and a take that empties
  // an ended instance erases it from that map: the likeliest cause of a buffer that died in
  // std::_Rb_tree_increment (docs/performance.md, "Ended instances swept"). Sweeps are seconds
  // apart, and an instance whose writer only lapsed (its process starved) is back, as NEW,
  // with its writer's next refresh before it is old enough to be swept: no erase and insert.
  static constexpr std::chrono::seconds kEndedKept{10};
  static constexpr std::chrono::seconds kSweepEvery{5};
  void sweep_ended(fdds::DataReader* reader, std::chrono::steady_clock::time_point now) {
    if (now < next_sweep_) return;
    next_sweep_ = now + kSweepEvery;
    fdds::LoanableSequence<T> samples;
    fdds::SampleInfoSeq infos;
    for (auto it = ended_.begin(); it != ended_.end();) {
      if (now - it->second < kEndedKept) {
        ++it;
        continue;
      }
      // Only what was read: a sample that came since (the instance reborn) stays for the next drain.
      if (reader->take_instance(samples, infos, fdds::LENGTH_UNLIMITED, it->first, fdds::READ_SAMPLE_STATE,
                                fdds::ANY_VIEW_STATE, fdds::NOT_ALIVE_INSTANCE_STATE) == ReturnCode_t::RETCODE_OK) {
        reader->return_loan(samples, infos);
      }
      it = ended_.erase(it);
    }
  }

  using Guid = eprosima::fastrtps::rtps::GUID_t;
  enum class Verdict { take, drop, hold };
  struct Source {
    Guid writer;
    fdds::InstanceHandle_t instance;
    bool gone;  // the instance's end (its writers gone, or disposed)
    std::int64_t generation = 0;  // how many times the instance had ended when the sample came
  };
  struct Delivered {
    Guid writer;
    T sample;
    std::int64_t generation;
  };

  // An instance that ended and lived again during a drain comes back with no end to read:
  // its sample's generation is above the one last delivered, whose end was not said. Say it
  // before the comeback, as a reader that looked in between would have. (A drain started by
  // a data callback holds the reader's lock, so nothing arrives during it; one started by a
  // lapse or a writer that left does not.)
  static std::int64_t generation(const fdds::SampleInfo& info) {
    return std::int64_t{info.disposed_generation_count} + info.no_writers_generation_count;
  }
  void say_missed_end(const fdds::SampleInfo& info) {
    const auto it = delivered_.find(info.instance_handle);
    if (it != delivered_.end() && it->second.generation < generation(info)) say_end_of_delivered(info.instance_handle);
  }
  void say_end_of_delivered(const fdds::InstanceHandle_t& instance) {
    const auto it = delivered_.find(instance);
    if (it == delivered_.end()) return;
    const T last = it->second.sample;
    const Source source{it->second.writer, instance, true};
    const Verdict v = from_its_owner(last, source);
    if (v == Verdict::take) {
      remember(last, source);
      if (on_gone_) on_gone_(last);
    }
    if (v == Verdict::hold) hold(last, source);
  }

  // State topics: whether `sample` is what its writer last delivered of its instance (the
  // writer's refresh, Writer::refresh). The same state from another writer is news: a process
  // started anew says it is there, before its old self's lease has run out.
  bool repeats(const T& sample, const Source& from) const {
    if (kind_ != TopicKind::state || from.gone) return false;
    const auto it = delivered_.find(from.instance);
    return it != delivered_.end() && it->second.writer == from.writer && it->second.sample == sample;
  }
  void remember(const T& sample, const Source& from) {
    if (kind_ != TopicKind::state) return;
    if (from.gone) delivered_.erase(from.instance);
    else delivered_.insert_or_assign(from.instance, Delivered{from.writer, sample, from.generation});
  }

  // Under DDS-Security a resource may write an owned topic (or one it speaks on for itself) in
  // its own partition only, a twin its order's topics in its own; a sample written for another
  // resource is dropped (the writer said once, on stderr). An order's sample waits while its
  // order is bound to no twin, or to another than its writer's: the binding of a twin started
  // anew for the order (another identity) may come after the new twin's first samples. An
  // instance's end counts from a writer whose samples of that instance counted before: the
  // order of a twin that died may be bound to the next twin by then.
  Verdict from_its_owner(const T& sample, const Source& from) {
    if (!check_writers_) return Verdict::take;
    if (from.gone && trusted_.erase({from.writer, from.instance}) > 0) return Verdict::take;
    const std::optional<std::string> speaker = speaker_(sample);
    if (!speaker) return Verdict::hold;
    if (writer_speaks_for(*participant_, from.writer, *speaker)) {
      if (kind_ == TopicKind::state) trusted_.insert({from.writer, from.instance});
      return Verdict::take;
    }
    if (impostors_.insert(from.writer).second) {
      std::cerr << (bindings_ ? "held" : "dropped") << " a sample on " << topic_ << " for '" << *speaker << "' from writer "
                << from.writer << ", which DDS-Security lets write only for another"
                << (bindings_ ? " (it counts only once its order is bound to its writer)" : "") << "\n";
    }
    return bindings_ ? Verdict::hold : Verdict::drop;
  }

  struct Held {
    T sample;
    Source from;
    std::chrono::steady_clock::time_point since;
  };
  // A binding comes within milliseconds of its twin's first samples. One held longer is not
  // kept for a later binding: a twin that wrote for another order while its identity was
  // bound elsewhere must not have those samples count once the identity is bound to that
  // order (identities go back to a pool).
  static constexpr std::size_t kHeld = 64;
  static constexpr std::chrono::seconds kHoldFor{5};

  void hold(const T& sample, const Source& from) {
    if (kind_ == TopicKind::state && !from.gone) {  // a writer's refresh replaces the state it held last
      const auto last = std::find_if(held_.rbegin(), held_.rend(), [&](const Held& h) {
        return h.from.writer == from.writer && h.from.instance == from.instance;
      });
      if (last != held_.rend() && !last->from.gone) {
        last->sample = sample;
        return;
      }
    }
    if (held_.size() >= kHeld) {
      std::cerr << "dropped a sample on " << topic_ << " from writer " << held_.front().from.writer
                << ": its order was bound to no twin, or to another, while " << kHeld << " more came\n";
      held_.pop_front();
    }
    held_.push_back({sample, from, std::chrono::steady_clock::now()});
  }

  // After a new binding: the held samples whose order is bound to their writer now, in the
  // order they came.
  void deliver_held_if_bound() {
    if (held_.empty() || !bindings_ || bindings_->generation() == held_checked_at_) return;
    held_checked_at_ = bindings_->generation();
    deliver_held();
  }
  void deliver_held() {
    std::deque<Held> waiting;
    const auto now = std::chrono::steady_clock::now();
    while (!held_.empty()) {
      Held h = std::move(held_.front());
      held_.pop_front();
      if (now - h.since > kHoldFor) {
        std::cerr << "dropped a sample on " << topic_ << " from writer " << h.from.writer << ": its order was not bound to "
                  << "its writer within " << kHoldFor.count() << " s\n";
        continue;
      }
      if (repeats(h.sample, h.from)) continue;
      const Verdict v = from_its_owner(h.sample, h.from);
      const auto& deliver = h.from.gone ? on_gone_ : on_sample_;
      if (v == Verdict::take) {
        remember(h.sample, h.from);
        if (deliver) deliver(h.sample);
      }
      if (v == Verdict::hold) waiting.push_back(std::move(h));
    }
    held_ = std::move(waiting);
  }

  ParticipantPtr participant_;
  TopicKind kind_;
  Speaker<T> speaker_;
  bool check_writers_ = false;
  std::string topic_;
  // Used by the draining thread only:
  std::set<eprosima::fastrtps::rtps::GUID_t> impostors_;
  // State topics: the instances each writer spoke for with the right to, until their end.
  std::set<std::pair<eprosima::fastrtps::rtps::GUID_t, fdds::InstanceHandle_t>> trusted_;
  std::deque<Held> held_;
  // State topics: each live instance's last delivered sample, its writer and generation.
  std::map<fdds::InstanceHandle_t, Delivered> delivered_;
  // State topics: the ended instances whose end was said, since when; and the next sweep.
  std::map<fdds::InstanceHandle_t, std::chrono::steady_clock::time_point> ended_;
  std::chrono::steady_clock::time_point next_sweep_{};
  unsigned held_checked_at_ = 0;  // the bindings' generation the held samples were last checked at
  std::shared_ptr<TwinBindings> bindings_;
  int listener_ = -1;
  std::function<void(const T&)> on_sample_;
  std::function<void(const T&)> on_gone_;
  std::atomic<int> requests_{0};  // drain calls not yet served
  std::atomic<bool> ends_announced_{false};
  const bool keyed_ = PubSubType().m_isGetKeyDefined;
  std::atomic<bool> closed_{false};
  fdds::Subscriber* subscriber_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
};

}  // namespace dds
